//! [`FreeForm`] elements → OBJ text. Every element gets its own `o` name, `# prespline`
//! settings, kept `vp` and `curv2` statements, `v` statements right before it, and its kept body
//! statements inside it; `con` statements close the file. Numbers are written in Rust's shortest
//! round-trip form, so reading the file back reproduces every value bit for bit; every vertex,
//! `curv2` and `surf` number is absolute (counted from 1 through the file).

use super::kept::{Body, Curve2, CurveRef, ObjKept, Technique};
use super::model::FreeForm;
use crate::fields::write::number;
use std::fmt::Write;

/// Statement lines longer than this are continued with `\`.
const WIDTH: usize = 100;

/// Serialises elements, with one entry per kept statement that had to be left out.
pub fn write(elements: &[FreeForm]) -> (String, Vec<String>) {
    let mut w = Writer::new(elements);
    for (i, e) in elements.iter().enumerate() {
        w.element(i, e);
    }
    w.connections();
    (w.s, w.dropped)
}

/// The file being written and the OBJ state it has set so far.
struct Writer<'a> {
    s: String,
    elements: &'a [FreeForm],
    /// Per element: its kept data when that is consistent (otherwise it is left out).
    kept: Vec<Option<&'a ObjKept>>,
    /// Per element: the file-wide number of its first `curv2` minus one.
    curve_base: Vec<usize>,
    /// Per element: its `surf` number, for surfaces.
    surface_number: Vec<Option<usize>>,
    /// The next `v` and `vp` numbers.
    next_v: usize,
    next_vp: usize,
    /// The `ctech` and `stech` in effect.
    ctech: Option<Technique>,
    stech: Option<Technique>,
    dropped: Vec<String>,
}

impl<'a> Writer<'a> {
    fn new(elements: &'a [FreeForm]) -> Self {
        let mut dropped = Vec::new();
        let kept: Vec<Option<&ObjKept>> = elements
            .iter()
            .map(|e| match e.carried.check(e.is_surface()) {
                Ok(()) => Some(&e.carried),
                Err(why) => {
                    dropped.push(format!(
                        "object '{}': its kept OBJ statements ({why})",
                        e.name.as_deref().unwrap_or("")
                    ));
                    None
                }
            })
            .collect();
        let mut curve_base = Vec::with_capacity(elements.len());
        let mut curves = 0;
        for k in &kept {
            curve_base.push(curves);
            curves += k.map_or(0, |c| c.curves2.len());
        }
        let mut surfaces = 0;
        let surface_number = elements
            .iter()
            .map(|e| {
                e.is_surface().then(|| {
                    surfaces += 1;
                    surfaces
                })
            })
            .collect();
        let s = format!(
            "# Wavefront OBJ free-form geometry written by prespline {}\n\
             # Rational elements carry their weights as the fourth v coordinate; see docs/obj.md.\n",
            env!("CARGO_PKG_VERSION")
        );
        Self {
            s,
            elements,
            kept,
            curve_base,
            surface_number,
            next_v: 1,
            next_vp: 1,
            ctech: None,
            stech: None,
            dropped,
        }
    }

    fn element(&mut self, i: usize, e: &FreeForm) {
        let s = &mut self.s;
        s.push('\n');
        if let Some(name) = &e.name {
            let _ = writeln!(s, "o {}", super::map::encode_name(name));
        }
        if let Some(m) = &e.samples {
            let counts: Vec<String> = m.iter().map(ToString::to_string).collect();
            let _ = writeln!(s, "# prespline samples {}", counts.join(" "));
        }
        if let Some(c) = e.color {
            let _ = writeln!(s, "# prespline color {}", join(&c));
        }
        let kept = self.kept[i];
        let vp_base = self.next_vp - 1;
        if let Some(k) = kept {
            self.parameter_vertices(k);
            for c in &k.curves2 {
                self.curve2(i, c, vp_base);
            }
        }
        let s = &mut self.s;
        for (p, &w) in e.points.iter().zip(&e.weights) {
            let _ = write!(s, "v {}", join(&p.to_array()));
            if e.rational {
                let _ = write!(s, " {}", number(w));
            }
            s.push('\n');
        }
        let name = e.name.as_deref().unwrap_or("");
        self.technique(
            e.is_surface(),
            kept.and_then(|k| k.technique.as_ref()),
            name,
        );
        let s = &mut self.s;
        let _ = writeln!(
            s,
            "cstype {}{}",
            if e.rational { "rat " } else { "" },
            e.basis.word()
        );
        let degrees: Vec<String> = e.dirs.iter().map(|d| d.degree.to_string()).collect();
        let _ = writeln!(s, "deg {}", degrees.join(" "));
        let mut words: Vec<String> = vec![e.keyword().to_string()];
        for d in &e.dirs {
            words.extend(d.range.iter().map(|&x| number(x)));
        }
        words.extend((self.next_v..self.next_v + e.points.len()).map(|i| i.to_string()));
        self.next_v += e.points.len();
        statement(s, &words);
        for (d, uv) in e.dirs.iter().zip(["u", "v"]) {
            let mut words = vec!["parm".to_string(), uv.to_string()];
            words.extend(d.parm.iter().map(|&x| number(x)));
            statement(s, &words);
        }
        if let Some(k) = kept {
            self.body(&k.body, self.curve_base[i], vp_base);
        }
        self.s.push_str("end\n");
    }

    fn parameter_vertices(&mut self, k: &ObjKept) {
        for p in &k.parameter_vertices {
            let _ = writeln!(self.s, "vp {}", join(p));
        }
        self.next_vp += k.parameter_vertices.len();
    }

    /// A kept `curv2` of element `i`, whose parameter vertices follow `vp_base`.
    fn curve2(&mut self, i: usize, c: &Curve2, vp_base: usize) {
        let name = self.elements[i].name.as_deref().unwrap_or("");
        self.technique(false, c.technique.as_ref(), name);
        let s = &mut self.s;
        let _ = writeln!(s, "cstype {}", c.cstype());
        let _ = writeln!(s, "deg {}", c.degree);
        let mut words = vec!["curv2".to_string()];
        words.extend(c.vertices.iter().map(|v| (vp_base + v + 1).to_string()));
        statement(s, &words);
        let mut words = vec!["parm".to_string(), "u".to_string()];
        words.extend(c.parm.iter().map(|&x| number(x)));
        statement(s, &words);
        self.body(&c.body, self.curve_base[i], vp_base);
        self.s.push_str("end\n");
    }

    /// Body statements with local numbers made file-wide.
    fn body(&mut self, body: &[Body], curve_base: usize, vp_base: usize) {
        for b in body {
            let mut words = vec![b.keyword().to_string()];
            match b {
                Body::Sp(points) => {
                    words.extend(points.iter().map(|p| (vp_base + p + 1).to_string()));
                }
                _ => {
                    for c in b.curves() {
                        words.extend(curve_words(c, curve_base));
                    }
                }
            }
            statement(&mut self.s, &words);
        }
    }

    /// Sets the technique in effect for the next curve (surface) to `t`. A technique cannot be
    /// unset in OBJ: an element without one after one with one gets it too, which is said.
    fn technique(&mut self, surface: bool, t: Option<&Technique>, name: &str) {
        let keyword = Technique::keyword(surface);
        let state = if surface {
            &mut self.stech
        } else {
            &mut self.ctech
        };
        match t {
            Some(t) if state.as_ref() != Some(t) => {
                let mut words = vec![keyword.to_string(), t.name.clone()];
                words.extend(t.values.iter().map(|&x| number(x)));
                statement(&mut self.s, &words);
                *state = Some(t.clone());
            }
            None if state.is_some() => self.dropped.push(format!(
                "object '{name}': its lack of a {keyword} (OBJ cannot unset the {keyword} written before it, so readers apply that one)"
            )),
            _ => {}
        }
    }

    /// The `con` statements of every surface, after all elements (they name surfaces by
    /// number); one whose other surface is not in the scene is left out and said.
    fn connections(&mut self) {
        let mut lines = Vec::new();
        for (i, e) in self.elements.iter().enumerate() {
            let (Some(k), Some(here)) = (self.kept[i], self.surface_number[i]) else {
                continue;
            };
            for c in &k.connections {
                let name = e.name.as_deref().unwrap_or("");
                match self.other_side(&c.surface, &c.surface_curve) {
                    Ok((there, base)) => {
                        let mut words = vec!["con".to_string(), here.to_string()];
                        words.extend(curve_words(&c.curve, self.curve_base[i]));
                        words.push(there.to_string());
                        words.extend(curve_words(&c.surface_curve, base));
                        lines.push(words);
                    }
                    Err(why) => self.dropped.push(format!(
                        "object '{name}': its con to '{}' ({why})",
                        c.surface
                    )),
                }
            }
        }
        if !lines.is_empty() {
            self.s.push('\n');
            for words in lines {
                statement(&mut self.s, &words);
            }
        }
    }

    /// The `surf` number and `curv2` base of the surface named `name`, if it is written with
    /// the curve `edge` names.
    fn other_side(&self, name: &str, edge: &CurveRef) -> Result<(usize, usize), String> {
        let j = self
            .elements
            .iter()
            .position(|e| e.name.as_deref() == Some(name))
            .ok_or_else(|| format!("no object '{name}' in the scene"))?;
        let number = self.surface_number[j].ok_or_else(|| format!("'{name}' is a curve"))?;
        let curves = self.kept[j].map_or(0, |k| k.curves2.len());
        if edge.curve >= curves {
            return Err(format!(
                "'{name}' has no kept curve {} ({curves} curves)",
                edge.curve
            ));
        }
        Ok((number, self.curve_base[j]))
    }
}

/// `u0 u1 curv2d` with the curve number made file-wide.
fn curve_words(c: &CurveRef, curve_base: usize) -> [String; 3] {
    [
        number(c.range[0]),
        number(c.range[1]),
        (curve_base + c.curve + 1).to_string(),
    ]
}

/// One statement, wrapped with `\` continuation lines.
fn statement(s: &mut String, words: &[String]) {
    let mut width = 0;
    for (i, w) in words.iter().enumerate() {
        if i > 0 {
            if width + 1 + w.len() > WIDTH {
                s.push_str(" \\\n   ");
                width = 3;
            }
            s.push(' ');
            width += 1;
        }
        s.push_str(w);
        width += w.len();
    }
    s.push('\n');
}

fn join(v: &[f64]) -> String {
    v.iter().map(|&x| number(x)).collect::<Vec<_>>().join(" ")
}
