//! What an OBJ element holds that prespline does not use — trimming loops and holes, special
//! curves and points, the `curv2` curves and `vp` parameter vertices they name, the curve or
//! surface approximation technique, surface connectivity — kept with its scene object so that
//! every save writes it back (docs/obj.md, "Kept and written back").
//!
//! Every reference is local to the object: a parameter vertex number indexes its own
//! `parameter_vertices`, a curve number its own `curves2` (0-based), so the data stays valid
//! whatever else the scene holds; the writer renumbers them into the file's global numbering.
//! Trims live in the surface's parameter space, and knot insertion, degree elevation and point
//! moves keep the domain, so they stay valid through edits.

use crate::fields::write::number;
use crate::scene::SceneError;
use crate::scene::json::{At, as_array, as_f64, as_object, as_str, as_usize, check_fields};
use serde_json::{Map, Value};

/// The kept data of one object; empty for objects that came from anywhere else.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ObjKept {
    /// `vp u [v [w]]`: one to three values each, in file order.
    pub parameter_vertices: Vec<Vec<f64>>,
    /// The `curv2` elements the object's statements name, and `curv2` elements nothing names
    /// (kept with the element that follows them in the file).
    pub curves2: Vec<Curve2>,
    /// `trim`, `hole`, `scrv` and `sp` of the element's body, in file order.
    pub body: Vec<Body>,
    /// `ctech` (curves) or `stech` (surfaces) in effect for the element.
    pub technique: Option<Technique>,
    /// `con` statements joining this surface to another (or to itself, along a seam).
    pub connections: Vec<Connection>,
}

/// A body statement.
#[derive(Debug, Clone, PartialEq)]
pub enum Body {
    /// `trim u0 u1 curv2d …`: one outer trimming loop.
    Trim(Vec<CurveRef>),
    /// `hole u0 u1 curv2d …`: one inner trimming loop.
    Hole(Vec<CurveRef>),
    /// `scrv u0 u1 curv2d …`: one special curve.
    Scrv(Vec<CurveRef>),
    /// `sp vp …`: special points (parameter vertex numbers).
    Sp(Vec<usize>),
}

/// The body statement keywords, in the order [`Body`] lists them.
pub const BODY_KEYWORDS: [&str; 4] = ["trim", "hole", "scrv", "sp"];

impl Body {
    #[must_use]
    pub fn keyword(&self) -> &'static str {
        match self {
            Body::Trim(_) => "trim",
            Body::Hole(_) => "hole",
            Body::Scrv(_) => "scrv",
            Body::Sp(_) => "sp",
        }
    }

    /// The curve references of `trim`/`hole`/`scrv` (none for `sp`).
    #[must_use]
    pub fn curves(&self) -> &[CurveRef] {
        match self {
            Body::Trim(c) | Body::Hole(c) | Body::Scrv(c) => c,
            Body::Sp(_) => &[],
        }
    }

    /// The parameter vertex numbers of `sp` (none otherwise).
    #[must_use]
    pub fn points(&self) -> &[usize] {
        match self {
            Body::Sp(p) => p,
            _ => &[],
        }
    }

    /// The statement of `keyword` with curve references or points.
    #[must_use]
    pub fn new(keyword: &str, curves: Vec<CurveRef>, points: Vec<usize>) -> Option<Body> {
        match keyword {
            "trim" => Some(Body::Trim(curves)),
            "hole" => Some(Body::Hole(curves)),
            "scrv" => Some(Body::Scrv(curves)),
            "sp" => Some(Body::Sp(points)),
            _ => None,
        }
    }
}

/// `u0 u1 curv2d`: the part [u0, u1] of curve `curve` (an index into `curves2`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveRef {
    pub range: [f64; 2],
    pub curve: usize,
}

/// `ctech` / `stech`: a technique name and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Technique {
    pub name: String,
    pub values: Vec<f64>,
}

/// `ctech` techniques with their value counts (the OBJ specification's list).
const CURVE_TECHNIQUES: [(&str, usize); 3] = [("cparm", 1), ("cspace", 1), ("curv", 2)];
/// `stech` techniques with their value counts.
const SURFACE_TECHNIQUES: [(&str, usize); 4] =
    [("cparma", 2), ("cparmb", 1), ("cspace", 1), ("curv", 2)];

impl Technique {
    /// `ctech` for curves and `curv2`, `stech` for surfaces.
    #[must_use]
    pub fn keyword(surface: bool) -> &'static str {
        if surface { "stech" } else { "ctech" }
    }

    /// Checks the name and the number of values against the specification's list.
    pub fn check(&self, surface: bool) -> Result<(), String> {
        let table: &[(&str, usize)] = if surface {
            &SURFACE_TECHNIQUES
        } else {
            &CURVE_TECHNIQUES
        };
        let word = Technique::keyword(surface);
        let Some(&(_, n)) = table.iter().find(|(name, _)| *name == self.name) else {
            let names: Vec<&str> = table.iter().map(|(name, _)| *name).collect();
            return Err(format!(
                "{word}: unknown technique '{}' (expected one of: {})",
                self.name,
                names.join(", ")
            ));
        };
        if self.values.len() != n {
            return Err(format!(
                "{word} {} takes {n} value(s), found {}",
                self.name,
                self.values.len()
            ));
        }
        Ok(())
    }
}

/// A `curv2` element: a curve in a surface's parameter space.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve2 {
    /// `cstype rat …`.
    pub rational: bool,
    /// The `cstype` word: bezier, bspline, bmatrix, cardinal or taylor.
    pub basis: String,
    pub degree: usize,
    /// Its control points: indices into `parameter_vertices`.
    pub vertices: Vec<usize>,
    /// `parm u`.
    pub parm: Vec<f64>,
    /// Its own body statements (`sp` in practice).
    pub body: Vec<Body>,
    /// `ctech` in effect for it.
    pub technique: Option<Technique>,
}

/// The `cstype` words a `curv2` may carry.
pub const CSTYPES: [&str; 5] = ["bezier", "bspline", "bmatrix", "cardinal", "taylor"];

impl Curve2 {
    /// `[rat ]basis`, as the `cstype` line writes it.
    #[must_use]
    pub fn cstype(&self) -> String {
        format!("{}{}", if self.rational { "rat " } else { "" }, self.basis)
    }
}

/// `con surf_1 q0_1 q1_1 curv2d_1 surf_2 q0_2 q1_2 curv2d_2`, kept with surf_1.
#[derive(Debug, Clone, PartialEq)]
pub struct Connection {
    /// The edge on this surface (`curve` indexes this object's `curves2`).
    pub curve: CurveRef,
    /// The other surface's object name.
    pub surface: String,
    /// The edge on the other surface (`curve` indexes *its* `curves2`).
    pub surface_curve: CurveRef,
}

impl ObjKept {
    #[must_use]
    pub fn is_empty(&self) -> bool {
        *self == ObjKept::default()
    }

    /// Every local reference in range, every technique and `cstype` known, every parameter
    /// vertex one to three values; connections only on surfaces. Names of other surfaces are
    /// checked by whoever knows the scene.
    pub fn check(&self, surface: bool) -> Result<(), String> {
        for (i, p) in self.parameter_vertices.iter().enumerate() {
            if !(1..=3).contains(&p.len()) {
                return Err(format!(
                    "parameter vertex {i} has {} values; vp takes 1 to 3",
                    p.len()
                ));
            }
        }
        self.check_body(&self.body, "body")?;
        if let Some(t) = &self.technique {
            t.check(surface)?;
        }
        for (k, c) in self.curves2.iter().enumerate() {
            if !CSTYPES.contains(&c.basis.as_str()) {
                return Err(format!(
                    "curve {k}: unknown cstype '{}' (expected one of: {})",
                    c.basis,
                    CSTYPES.join(", ")
                ));
            }
            if c.vertices.is_empty() {
                return Err(format!("curve {k}: no vertices"));
            }
            if let Some(&v) = c
                .vertices
                .iter()
                .find(|&&v| v >= self.parameter_vertices.len())
            {
                return Err(format!(
                    "curve {k}: vertex {v} does not exist ({} parameter vertices)",
                    self.parameter_vertices.len()
                ));
            }
            self.check_body(&c.body, &format!("curve {k} body"))?;
            if let Some(t) = &c.technique {
                t.check(false).map_err(|e| format!("curve {k}: {e}"))?;
            }
        }
        if !surface && !self.connections.is_empty() {
            return Err("connections join surfaces; this object is a curve".into());
        }
        for (k, c) in self.connections.iter().enumerate() {
            self.check_curve(&c.curve)
                .map_err(|e| format!("connection {k}: {e}"))?;
        }
        Ok(())
    }

    fn check_body(&self, body: &[Body], what: &str) -> Result<(), String> {
        for (k, b) in body.iter().enumerate() {
            let at = |e: String| format!("{what} {k} ({}): {e}", b.keyword());
            if b.curves().is_empty() && b.points().is_empty() {
                return Err(at("no references".into()));
            }
            for c in b.curves() {
                self.check_curve(c).map_err(at)?;
            }
            if let Some(&p) = b
                .points()
                .iter()
                .find(|&&p| p >= self.parameter_vertices.len())
            {
                return Err(at(format!(
                    "parameter vertex {p} does not exist ({} parameter vertices)",
                    self.parameter_vertices.len()
                )));
            }
        }
        Ok(())
    }

    fn check_curve(&self, c: &CurveRef) -> Result<(), String> {
        if c.curve >= self.curves2.len() {
            return Err(format!(
                "curve {} does not exist ({} curves)",
                c.curve,
                self.curves2.len()
            ));
        }
        Ok(())
    }
}

impl crate::scene::Kept for ObjKept {
    fn key(&self) -> &'static str {
        "obj"
    }

    fn to_json(&self) -> String {
        to_json(self)
    }

    crate::kept_boilerplate!();

    /// Every `con` joins this surface to a surface of the scene along a curve that one keeps.
    fn check_scene(&self, names: &crate::scene::SceneNames<'_>, _me: usize) -> Result<(), String> {
        for (k, c) in self.connections.iter().enumerate() {
            let other = names
                .find(&c.surface)
                .and_then(|i| names.objects.get(i))
                .ok_or_else(|| format!("connections[{k}]: no object named '{}'", c.surface))?;
            if !other.model.is_surface() {
                return Err(format!(
                    "connections[{k}]: '{}' is not a surface",
                    c.surface
                ));
            }
            let curves = other.kept.get::<ObjKept>().map_or(0, |o| o.curves2.len());
            if c.surface_curve.curve >= curves {
                return Err(format!(
                    "connections[{k}]: '{}' keeps no curve {} ({curves} curves)",
                    c.surface, c.surface_curve.curve
                ));
            }
        }
        Ok(())
    }
}

// ---- JSON (docs/scene-format.md, field `obj`) ---------------------------------------------

/// The `obj` field's value.
pub fn to_json(c: &ObjKept) -> String {
    let mut fields = Vec::new();
    if !c.parameter_vertices.is_empty() {
        let vp: Vec<String> = c.parameter_vertices.iter().map(|p| numbers(p)).collect();
        fields.push(format!("\"parameter_vertices\": [{}]", vp.join(", ")));
    }
    if !c.curves2.is_empty() {
        let curves: Vec<String> = c.curves2.iter().map(curve2_json).collect();
        fields.push(format!("\"curves2\": [{}]", curves.join(", ")));
    }
    if !c.body.is_empty() {
        fields.push(format!("\"body\": {}", body_json(&c.body)));
    }
    if let Some(t) = &c.technique {
        fields.push(format!("\"technique\": {}", technique_json(t)));
    }
    if !c.connections.is_empty() {
        let con: Vec<String> = c
            .connections
            .iter()
            .map(|k| {
                format!(
                    "{{\"curve\": {}, \"surface\": {}, \"surface_curve\": {}}}",
                    curve_ref_json(&k.curve),
                    Value::String(k.surface.clone()),
                    curve_ref_json(&k.surface_curve)
                )
            })
            .collect();
        fields.push(format!("\"connections\": [{}]", con.join(", ")));
    }
    format!("{{{}}}", fields.join(", "))
}

fn curve2_json(c: &Curve2) -> String {
    let vertices: Vec<String> = c.vertices.iter().map(ToString::to_string).collect();
    let mut s = format!(
        "{{\"cstype\": {}, \"degree\": {}, \"vertices\": [{}], \"parm\": {}",
        Value::String(c.cstype()),
        c.degree,
        vertices.join(", "),
        numbers(&c.parm)
    );
    if !c.body.is_empty() {
        s.push_str(&format!(", \"body\": {}", body_json(&c.body)));
    }
    if let Some(t) = &c.technique {
        s.push_str(&format!(", \"technique\": {}", technique_json(t)));
    }
    s.push('}');
    s
}

fn body_json(body: &[Body]) -> String {
    let items: Vec<String> = body
        .iter()
        .map(|b| {
            let args: Vec<String> = match b {
                Body::Sp(p) => p.iter().map(ToString::to_string).collect(),
                _ => b.curves().iter().map(curve_ref_json).collect(),
            };
            format!("{{\"{}\": [{}]}}", b.keyword(), args.join(", "))
        })
        .collect();
    format!("[{}]", items.join(", "))
}

fn technique_json(t: &Technique) -> String {
    format!(
        "{{\"name\": {}, \"values\": {}}}",
        Value::String(t.name.clone()),
        numbers(&t.values)
    )
}

fn curve_ref_json(c: &CurveRef) -> String {
    format!(
        "[{}, {}, {}]",
        number(c.range[0]),
        number(c.range[1]),
        c.curve
    )
}

fn numbers(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|&x| number(x)).collect();
    format!("[{}]", items.join(", "))
}

/// Parses the `obj` field of an object (`surface`: whether the object is one).
pub fn from_json(at: &At, v: &Value, surface: bool) -> Result<ObjKept, SceneError> {
    const FIELD: &str = "obj";
    let obj = as_object(at, FIELD, v)?;
    let inner = At(format!("{}: field 'obj'", at.0));
    check_fields(
        &inner,
        obj,
        &[
            "parameter_vertices",
            "curves2",
            "body",
            "technique",
            "connections",
        ],
    )?;
    let err = |msg: String| at.err(FIELD, msg);
    let list = |name: &str| -> Result<&[Value], SceneError> {
        obj.get(name)
            .map_or(Ok(&[][..]), |v| as_array(at, FIELD, v).map(Vec::as_slice))
    };
    let parameter_vertices = list("parameter_vertices")?
        .iter()
        .enumerate()
        .map(|(i, p)| floats(at, &format!("parameter_vertices[{i}]"), p))
        .collect::<Result<_, _>>()?;
    let curves2 = list("curves2")?
        .iter()
        .enumerate()
        .map(|(k, c)| curve2_from_json(at, k, c))
        .collect::<Result<_, _>>()?;
    let body = body_from_json(at, "body", list("body")?)?;
    let technique = obj
        .get("technique")
        .map(|t| technique_from_json(at, "technique", t))
        .transpose()?;
    let connections = list("connections")?
        .iter()
        .enumerate()
        .map(|(k, c)| connection_from_json(at, k, c))
        .collect::<Result<_, _>>()?;
    let carried = ObjKept {
        parameter_vertices,
        curves2,
        body,
        technique,
        connections,
    };
    carried.check(surface).map_err(err)?;
    Ok(carried)
}

fn curve2_from_json(at: &At, k: usize, v: &Value) -> Result<Curve2, SceneError> {
    let what = format!("curves2[{k}]");
    let c = as_object(at, "obj", v)?;
    let inner = At(format!("{}: field 'obj': {what}", at.0));
    check_fields(
        &inner,
        c,
        &["cstype", "degree", "vertices", "parm", "body", "technique"],
    )?;
    let need = |name: &str| {
        c.get(name)
            .ok_or_else(|| at.err("obj", format!("{what}: missing '{name}'")))
    };
    let cstype = as_str(at, "obj", need("cstype")?)?;
    let (rational, basis) = match cstype.split_whitespace().collect::<Vec<_>>().as_slice() {
        ["rat", b] => (true, (*b).to_string()),
        [b] => (false, (*b).to_string()),
        _ => {
            return Err(at.err(
                "obj",
                format!("{what}: cstype '{cstype}' is not [rat] <type>"),
            ));
        }
    };
    let degree = as_usize(at, "obj", format_args!("{what} degree"), need("degree")?)?;
    let vertices = as_array(at, "obj", need("vertices")?)?
        .iter()
        .enumerate()
        .map(|(i, x)| as_usize(at, "obj", format_args!("{what} vertex {i}"), x))
        .collect::<Result<_, _>>()?;
    let parm = floats(at, &format!("{what} parm"), need("parm")?)?;
    let body = match c.get("body") {
        Some(b) => body_from_json(at, &format!("{what} body"), as_array(at, "obj", b)?)?,
        None => Vec::new(),
    };
    let technique = c
        .get("technique")
        .map(|t| technique_from_json(at, &format!("{what} technique"), t))
        .transpose()?;
    Ok(Curve2 {
        rational,
        basis,
        degree,
        vertices,
        parm,
        body,
        technique,
    })
}

fn body_from_json(at: &At, what: &str, items: &[Value]) -> Result<Vec<Body>, SceneError> {
    items
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let what = format!("{what}[{k}]");
            let m: &Map<String, Value> = as_object(at, "obj", v)?;
            let (keyword, args) = match m.iter().next() {
                Some((key, args)) if m.len() == 1 => (key.as_str(), args),
                _ => {
                    return Err(at.err(
                        "obj",
                        format!(
                            "{what}: expected one of {{\"trim\" | \"hole\" | \"scrv\": [[u0, u1, curve], …]}} or {{\"sp\": [vertex, …]}}"
                        ),
                    ));
                }
            };
            if !BODY_KEYWORDS.contains(&keyword) {
                return Err(at.err(
                    "obj",
                    format!(
                        "{what}: unknown statement '{keyword}' (expected one of: {})",
                        BODY_KEYWORDS.join(", ")
                    ),
                ));
            }
            let args = as_array(at, "obj", args)?;
            let (mut curves, mut points) = (Vec::new(), Vec::new());
            if keyword == "sp" {
                for (i, x) in args.iter().enumerate() {
                    points.push(as_usize(at, "obj", format_args!("{what} sp {i}"), x)?);
                }
            } else {
                for (i, x) in args.iter().enumerate() {
                    curves.push(curve_ref_from_json(at, &format!("{what} {keyword} {i}"), x)?);
                }
            }
            Body::new(keyword, curves, points)
                .ok_or_else(|| at.err("obj", format!("{what}: unknown statement '{keyword}'")))
        })
        .collect()
}

fn technique_from_json(at: &At, what: &str, v: &Value) -> Result<Technique, SceneError> {
    let t = as_object(at, "obj", v)?;
    let inner = At(format!("{}: field 'obj': {what}", at.0));
    check_fields(&inner, t, &["name", "values"])?;
    let name = t
        .get("name")
        .ok_or_else(|| at.err("obj", format!("{what}: missing 'name'")))?;
    let values = t
        .get("values")
        .ok_or_else(|| at.err("obj", format!("{what}: missing 'values'")))?;
    Ok(Technique {
        name: as_str(at, "obj", name)?.to_string(),
        values: floats(at, &format!("{what} values"), values)?,
    })
}

fn connection_from_json(at: &At, k: usize, v: &Value) -> Result<Connection, SceneError> {
    let what = format!("connections[{k}]");
    let c = as_object(at, "obj", v)?;
    let inner = At(format!("{}: field 'obj': {what}", at.0));
    check_fields(&inner, c, &["curve", "surface", "surface_curve"])?;
    let need = |name: &str| {
        c.get(name)
            .ok_or_else(|| at.err("obj", format!("{what}: missing '{name}'")))
    };
    Ok(Connection {
        curve: curve_ref_from_json(at, &format!("{what} curve"), need("curve")?)?,
        surface: as_str(at, "obj", need("surface")?)?.to_string(),
        surface_curve: curve_ref_from_json(
            at,
            &format!("{what} surface_curve"),
            need("surface_curve")?,
        )?,
    })
}

/// `[u0, u1, curve]`.
fn curve_ref_from_json(at: &At, what: &str, v: &Value) -> Result<CurveRef, SceneError> {
    match v.as_array().map(Vec::as_slice) {
        Some([u0, u1, k]) => Ok(CurveRef {
            range: [
                as_f64(at, "obj", format_args!("{what} u0"), u0)?,
                as_f64(at, "obj", format_args!("{what} u1"), u1)?,
            ],
            curve: as_usize(at, "obj", format_args!("{what} curve"), k)?,
        }),
        _ => Err(at.err(
            "obj",
            format!("{what}: expected [u0, u1, curve], found {v}"),
        )),
    }
}

fn floats(at: &At, what: &str, v: &Value) -> Result<Vec<f64>, SceneError> {
    as_array(at, "obj", v)?
        .iter()
        .enumerate()
        .map(|(i, x)| as_f64(at, "obj", format_args!("{what} value {i}"), x))
        .collect()
}
