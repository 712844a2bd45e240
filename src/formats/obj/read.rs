//! Statements → [`FreeForm`] elements. The reader keeps the OBJ state (`cstype`, `deg`,
//! `ctech`/`stech`, the current name) and checks every element when its `end` arrives; vertex,
//! `curv2` and surface numbers are checked once the whole file is read, since a positive number
//! may name one written later. What prespline does not use — `trim`, `hole`, `scrv`, `sp`,
//! `curv2`, `vp`, `con`, `ctech`, `stech` — is resolved then and kept with the element it
//! belongs to ([`ObjKept`]).

use super::check;
use super::kept::{Body, Connection, Curve2, CurveRef, ObjKept, Technique};
use super::lex::{Statement, Token};
use super::model::{Basis, FreeForm};
use super::{ObjError, ObjWarning, Warnings};
use crate::scene::{MAX_CURVE_SAMPLES, MAX_DEGREE, MAX_SURFACE_SAMPLES};
use glam::DVec3;
use std::collections::{BTreeSet, HashMap, HashSet};

/// The elements of a file and what was ignored on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Parsed {
    pub elements: Vec<FreeForm>,
    pub warnings: Vec<ObjWarning>,
}

/// Reads the free-form elements of a statement list.
pub fn read(statements: &[Statement]) -> Result<Parsed, ObjError> {
    let mut r = Reader::default();
    for s in statements {
        r.statement(s)?;
    }
    r.finish()
}

/// Numbered vertex lists: `v`, `vt`, `vn`, `vp`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum VertexKind {
    Geometric,
    Texture,
    Normal,
    Parameter,
}

impl VertexKind {
    fn word(self) -> &'static str {
        match self {
            VertexKind::Geometric => "v",
            VertexKind::Texture => "vt",
            VertexKind::Normal => "vn",
            VertexKind::Parameter => "vp",
        }
    }
}

/// A `v` statement.
#[derive(Debug, Clone, Copy)]
struct Vertex {
    point: DVec3,
    weight: Option<f64>,
    line: usize,
}

/// A vertex number, made absolute (0-based); checked against the final count.
#[derive(Debug, Clone, Copy)]
struct VertexRef {
    kind: VertexKind,
    index: usize,
    line: usize,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum CsKind {
    Supported(Basis),
    Unsupported(&'static str),
}

impl CsKind {
    fn word(self) -> &'static str {
        match self {
            CsKind::Supported(b) => b.word(),
            CsKind::Unsupported(name) => name,
        }
    }
}

/// A `curv2` or `surf` number made absolute (0-based): an element's place among the file's
/// elements of its kind.
#[derive(Debug, Clone, Copy)]
struct ElementRef {
    index: usize,
    line: usize,
}

/// A `trim`, `hole`, `scrv` or `sp` statement with its numbers made absolute.
#[derive(Debug, Clone)]
struct BodyRead {
    keyword: &'static str,
    curves: Vec<([f64; 2], ElementRef)>,
    points: Vec<VertexRef>,
}

/// A `curv2` element, kept as written.
#[derive(Debug, Clone)]
struct Curve2Read {
    line: usize,
    cstype: CsType,
    degree: usize,
    vertices: Vec<VertexRef>,
    parm: Vec<f64>,
    body: Vec<BodyRead>,
    technique: Option<Technique>,
}

/// A `con` statement: two (surface, edge) sides.
#[derive(Debug, Clone)]
struct ConRead {
    line: usize,
    sides: [(ElementRef, [f64; 2], ElementRef); 2],
}

#[derive(Debug, Clone, Copy)]
struct CsType {
    kind: CsKind,
    rational: bool,
}

#[derive(Debug, Clone)]
struct Degrees {
    values: Vec<usize>,
    line: usize,
}

/// `# prespline` settings waiting for the next element.
#[derive(Debug, Clone, Default)]
struct Pending {
    samples: Option<(Vec<usize>, usize)>,
    color: Option<([f64; 3], usize)>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ElementKind {
    Curve,
    Surface,
    /// `curv2`: a curve in a surface's parameter space, only used for trimming; skipped.
    Curve2,
}

impl ElementKind {
    fn word(self) -> &'static str {
        match self {
            ElementKind::Curve => "curv",
            ElementKind::Surface => "surf",
            ElementKind::Curve2 => "curv2",
        }
    }
}

/// An element between its `curv`/`curv2`/`surf` and its `end`.
#[derive(Debug, Clone)]
struct Open {
    kind: ElementKind,
    line: usize,
    ranges: Vec<[f64; 2]>,
    refs: Vec<VertexRef>,
    parm: [Option<(Vec<f64>, usize)>; 2],
    cstype: Option<CsType>,
    degrees: Option<Degrees>,
    name: Option<String>,
    pending: Pending,
    body: Vec<BodyRead>,
    technique: Option<Technique>,
    /// A surface's place among the file's `surf` elements (counting skipped ones).
    surface: Option<usize>,
}

/// A checked element whose control vertices are resolved at the end of the file.
#[derive(Debug, Clone)]
struct Checked {
    element: FreeForm,
    refs: Vec<VertexRef>,
    body: Vec<BodyRead>,
}

#[derive(Debug, Default)]
struct Reader {
    vertices: Vec<Vertex>,
    /// `vp` values.
    params: Vec<Vec<f64>>,
    counts: [usize; 4],
    refs: Vec<VertexRef>,
    cstype: Option<CsType>,
    degrees: Option<Degrees>,
    ctech: Option<Technique>,
    stech: Option<Technique>,
    name: Option<String>,
    pending: Pending,
    open: Option<Open>,
    done: Vec<Checked>,
    curves2: Vec<Curve2Read>,
    /// Per `surf` element in file order: its index in `done`, `None` when it was skipped.
    surfaces: Vec<Option<usize>>,
    cons: Vec<ConRead>,
    warnings: Warnings,
}

impl Reader {
    fn statement(&mut self, s: &Statement) -> Result<(), ObjError> {
        if s.extension {
            return self.extension(s);
        }
        if let Some(open) = &self.open
            && !matches!(s.keyword, "parm" | "trim" | "hole" | "scrv" | "sp" | "end")
        {
            return Err(ObjError::new(
                open.line,
                format!(
                    "{} has no end: line {} starts '{}' before it",
                    open.kind.word(),
                    s.line,
                    s.keyword
                ),
            ));
        }
        match s.keyword {
            "v" => self.vertex(s),
            "vt" | "vn" | "vp" => self.other_vertex(s),
            "cstype" => self.cstype(s),
            "deg" => self.degrees(s),
            "curv" => self.open_element(s, ElementKind::Curve),
            "surf" => self.open_element(s, ElementKind::Surface),
            "curv2" => self.open_element(s, ElementKind::Curve2),
            "parm" => self.parm(s),
            "trim" | "hole" | "scrv" | "sp" => self.body(s),
            "end" => self.end(s),
            "o" | "g" => {
                let name = super::map::decode_name(&join(&s.args));
                self.name = (!name.is_empty()).then_some(name);
                Ok(())
            }
            "f" | "l" | "p" | "fo" => {
                self.warnings.add(s.keyword, s.line, || {
                    format!(
                        "'{}' statement ignored: prespline reads the free-form curves and surfaces of an OBJ file, not its polygons, lines or points",
                        s.keyword
                    )
                });
                Ok(())
            }
            "con" => self.con(s),
            "bmat" | "step" => {
                self.warnings.add(s.keyword, s.line, || {
                    format!(
                        "'{}' ignored: it belongs to cstype bmatrix, cardinal and taylor, which are not supported",
                        s.keyword
                    )
                });
                Ok(())
            }
            "ctech" | "stech" => self.technique(s),
            // Display and render attributes have no meaning for prespline's own display.
            "usemtl" | "mtllib" | "s" | "mg" | "lod" | "bevel" | "c_interp" | "d_interp"
            | "shadow_obj" | "trace_obj" | "maplib" | "usemap" => Ok(()),
            other => {
                self.warnings.add(&format!("?{other}"), s.line, || {
                    format!("unknown statement '{other}' ignored")
                });
                Ok(())
            }
        }
    }

    fn vertex(&mut self, s: &Statement) -> Result<(), ObjError> {
        let a = &s.args;
        if !matches!(a.len(), 3 | 4 | 6) {
            return Err(ObjError::new(
                s.line,
                format!(
                    "v takes x y z and an optional weight w, found {} values",
                    a.len()
                ),
            ));
        }
        let c = |i: usize| number(&a[i], &format!("v: coordinate {}", i + 1));
        let point = DVec3::new(c(0)?, c(1)?, c(2)?);
        let weight = match a.len() {
            4 => Some(number(&a[3], "v: weight")?),
            6 => {
                for (i, t) in a[3..].iter().enumerate() {
                    number(t, &format!("v: colour component {}", i + 1))?;
                }
                self.warnings.add("vertex colour", s.line, || {
                    "vertex colours (v x y z r g b) ignored".into()
                });
                None
            }
            _ => None,
        };
        self.vertices.push(Vertex {
            point,
            weight,
            line: s.line,
        });
        self.counts[0] += 1;
        Ok(())
    }

    fn other_vertex(&mut self, s: &Statement) -> Result<(), ObjError> {
        let range = if s.keyword == "vn" { 3..=3 } else { 1..=3 };
        if !range.contains(&s.args.len()) {
            return Err(ObjError::new(
                s.line,
                format!(
                    "{} takes {} values, found {}",
                    s.keyword,
                    if s.keyword == "vn" { "3" } else { "1 to 3" },
                    s.args.len()
                ),
            ));
        }
        let values = s
            .args
            .iter()
            .enumerate()
            .map(|(i, t)| number(t, &format!("{}: value {}", s.keyword, i + 1)))
            .collect::<Result<Vec<f64>, _>>()?;
        match s.keyword {
            "vt" => self.counts[1] += 1,
            "vn" => self.counts[2] += 1,
            _ => {
                // Kept for the `curv2` and `sp` statements that name it.
                self.params.push(values);
                self.counts[3] += 1;
            }
        }
        Ok(())
    }

    fn cstype(&mut self, s: &Statement) -> Result<(), ObjError> {
        let words: Vec<&str> = s.args.iter().map(|t| t.text).collect();
        let (rational, name) = match words.as_slice() {
            ["rat", name] => (true, *name),
            [name] => (false, *name),
            _ => {
                return Err(ObjError::new(
                    s.line,
                    "cstype takes [rat] bezier | bspline | bmatrix | cardinal | taylor",
                ));
            }
        };
        let kind = match name {
            "bezier" => CsKind::Supported(Basis::Bezier),
            "bspline" => CsKind::Supported(Basis::BSpline),
            "bmatrix" => CsKind::Unsupported("bmatrix"),
            "cardinal" => CsKind::Unsupported("cardinal"),
            "taylor" => CsKind::Unsupported("taylor"),
            other => {
                return Err(ObjError::new(
                    s.line,
                    format!(
                        "cstype: unknown type '{other}' (expected bezier, bspline, bmatrix, cardinal or taylor, optionally after rat)"
                    ),
                ));
            }
        };
        self.cstype = Some(CsType { kind, rational });
        Ok(())
    }

    fn degrees(&mut self, s: &Statement) -> Result<(), ObjError> {
        if !(1..=2).contains(&s.args.len()) {
            return Err(ObjError::new(
                s.line,
                format!(
                    "deg takes one degree (curves) or two (surfaces), found {} values",
                    s.args.len()
                ),
            ));
        }
        let mut values = Vec::new();
        for t in &s.args {
            let d: usize = t.text.parse().map_err(|_| {
                ObjError::new(t.line, format!("deg: '{}' is not a whole number", t.text))
            })?;
            if d == 0 || d > MAX_DEGREE {
                return Err(ObjError::new(
                    t.line,
                    format!("deg: degree {d} is outside the supported range 1..={MAX_DEGREE}"),
                ));
            }
            values.push(d);
        }
        self.degrees = Some(Degrees {
            values,
            line: s.line,
        });
        Ok(())
    }

    fn open_element(&mut self, s: &Statement, kind: ElementKind) -> Result<(), ObjError> {
        let word = kind.word();
        let nranges = match kind {
            ElementKind::Curve => 1,
            ElementKind::Surface => 2,
            ElementKind::Curve2 => 0,
        };
        if s.args.len() < 2 * nranges + 1 {
            return Err(ObjError::new(
                s.line,
                match kind {
                    ElementKind::Curve => {
                        "curv takes a parameter range u0 u1 and control vertex numbers".into()
                    }
                    ElementKind::Surface => {
                        "surf takes parameter ranges s0 s1 t0 t1 and control vertex numbers".into()
                    }
                    ElementKind::Curve2 => format!("{word} takes parameter vertex numbers"),
                },
            ));
        }
        let mut ranges = Vec::new();
        for d in 0..nranges {
            let a = number(&s.args[2 * d], &format!("{word}: range start"))?;
            let b = number(&s.args[2 * d + 1], &format!("{word}: range end"))?;
            ranges.push([a, b]);
        }
        let mut refs = Vec::new();
        for t in &s.args[2 * nranges..] {
            if kind == ElementKind::Curve2 {
                refs.push(self.resolve(VertexKind::Parameter, t.text, t)?);
            } else {
                self.element_ref(kind, t, &mut refs)?;
            }
        }
        // `# prespline` settings wait for the curv or surf they describe.
        let pending = match kind {
            ElementKind::Curve2 => Pending::default(),
            _ => std::mem::take(&mut self.pending),
        };
        let surface = (kind == ElementKind::Surface).then(|| {
            self.surfaces.push(None);
            self.surfaces.len() - 1
        });
        let technique = match kind {
            ElementKind::Surface => self.stech.clone(),
            _ => self.ctech.clone(),
        };
        self.open = Some(Open {
            kind,
            line: s.line,
            ranges,
            refs,
            parm: [None, None],
            cstype: self.cstype,
            degrees: self.degrees.clone(),
            name: self.name.clone(),
            pending,
            body: Vec::new(),
            technique,
            surface,
        });
        Ok(())
    }

    /// `v` for curves; `v`, `v/vt`, `v/vt/vn` or `v//vn` for surfaces (texture and normal
    /// numbers are checked, then ignored).
    fn element_ref(
        &mut self,
        kind: ElementKind,
        t: &Token,
        refs: &mut Vec<VertexRef>,
    ) -> Result<(), ObjError> {
        let parts: Vec<&str> = t.text.split('/').collect();
        if parts.len() > 1 && kind == ElementKind::Curve {
            return Err(ObjError::new(
                t.line,
                format!(
                    "curv: control vertex '{}' must be a plain vertex number",
                    t.text
                ),
            ));
        }
        if parts.len() > 3 {
            return Err(ObjError::new(
                t.line,
                format!("surf: '{}' is not v, v/vt, v/vt/vn or v//vn", t.text),
            ));
        }
        let kinds = [
            VertexKind::Geometric,
            VertexKind::Texture,
            VertexKind::Normal,
        ];
        for (i, part) in parts.iter().enumerate() {
            if part.is_empty() && i == 1 && parts.len() == 3 {
                continue; // v//vn
            }
            let r = self.resolve(kinds[i], part, t)?;
            if i == 0 {
                refs.push(r);
            } else {
                self.refs.push(r);
            }
        }
        Ok(())
    }

    /// A vertex number made absolute: 1 is the first vertex, −1 the latest one so far.
    fn resolve(&self, kind: VertexKind, text: &str, t: &Token) -> Result<VertexRef, ObjError> {
        let what = kind.word();
        let count = self.counts[kind as usize];
        let i: i64 = text.parse().map_err(|_| {
            ObjError::new(
                t.line,
                format!("'{}': '{text}' is not a {what} number", t.text),
            )
        })?;
        let index = match i {
            0 => {
                return Err(ObjError::new(
                    t.line,
                    format!(
                        "{what} number 0 is invalid: OBJ counts vertices from 1 (or back from -1)"
                    ),
                ));
            }
            i if i > 0 => usize::try_from(i - 1).unwrap_or(usize::MAX),
            i => match usize::try_from(i.unsigned_abs())
                .ok()
                .and_then(|back| count.checked_sub(back))
            {
                Some(index) => index,
                None => {
                    return Err(ObjError::new(
                        t.line,
                        format!(
                            "relative {what} number {i} reaches before the first one ({count} defined so far)"
                        ),
                    ));
                }
            },
        };
        Ok(VertexRef {
            kind,
            index,
            line: t.line,
        })
    }

    /// A `curv2` or `surf` number made absolute, like a vertex number: 1 is the first element
    /// of its kind in the file, −1 the latest one so far.
    fn element_number(what: &str, count: usize, t: &Token) -> Result<ElementRef, ObjError> {
        let i: i64 = t
            .text
            .parse()
            .map_err(|_| ObjError::new(t.line, format!("'{}' is not a {what} number", t.text)))?;
        let index = match i {
            0 => {
                return Err(ObjError::new(
                    t.line,
                    format!("{what} number 0 is invalid: OBJ counts elements from 1 (or back from -1)"),
                ));
            }
            i if i > 0 => usize::try_from(i - 1).unwrap_or(usize::MAX),
            i => usize::try_from(i.unsigned_abs())
                .ok()
                .and_then(|back| count.checked_sub(back))
                .ok_or_else(|| {
                    ObjError::new(
                        t.line,
                        format!(
                            "relative {what} number {i} reaches before the first one ({count} defined so far)"
                        ),
                    )
                })?,
        };
        Ok(ElementRef {
            index,
            line: t.line,
        })
    }

    fn parm(&mut self, s: &Statement) -> Result<(), ObjError> {
        let Some(open) = &mut self.open else {
            return Err(ObjError::new(
                s.line,
                "parm outside a curv or surf (before it, or after its end)",
            ));
        };
        let dir = match s.args.first().map(|t| t.text) {
            Some("u") => 0,
            Some("v") => 1,
            _ => return Err(ObjError::new(s.line, "parm takes u or v, then the values")),
        };
        if dir == 1 && open.kind != ElementKind::Surface {
            return Err(ObjError::new(
                s.line,
                format!(
                    "parm v: the {} at line {} has only a u direction",
                    open.kind.word(),
                    open.line
                ),
            ));
        }
        let uv = ["u", "v"][dir];
        if let Some((_, first)) = &open.parm[dir] {
            return Err(ObjError::new(
                s.line,
                format!(
                    "second parm {uv} for the {} at line {} (the first is at line {first})",
                    open.kind.word(),
                    open.line
                ),
            ));
        }
        if s.args.len() < 3 {
            return Err(ObjError::new(
                s.line,
                format!("parm {uv} needs at least two values"),
            ));
        }
        let values = s.args[1..]
            .iter()
            .enumerate()
            .map(|(i, t)| number(t, &format!("parm {uv}: value {}", i + 1)))
            .collect::<Result<Vec<_>, _>>()?;
        open.parm[dir] = Some((values, s.line));
        Ok(())
    }

    /// `trim`/`hole`/`scrv` (u0 u1 curv2d triples) or `sp` (vp numbers), kept with the
    /// element being read.
    fn body(&mut self, s: &Statement) -> Result<(), ObjError> {
        let Some(open) = &self.open else {
            return Err(ObjError::new(
                s.line,
                format!("{} outside a curv, curv2 or surf body", s.keyword),
            ));
        };
        let keyword = match s.keyword {
            "trim" => "trim",
            "hole" => "hole",
            "scrv" => "scrv",
            _ => "sp",
        };
        let mut body = BodyRead {
            keyword,
            curves: Vec::new(),
            points: Vec::new(),
        };
        if keyword == "sp" {
            if s.args.is_empty() {
                return Err(ObjError::new(s.line, "sp takes parameter vertex numbers"));
            }
            for t in &s.args {
                body.points
                    .push(self.resolve(VertexKind::Parameter, t.text, t)?);
            }
        } else {
            if s.args.is_empty() || !s.args.len().is_multiple_of(3) {
                return Err(ObjError::new(
                    s.line,
                    format!(
                        "{keyword} takes u0 u1 curv2d triples, found {} values",
                        s.args.len()
                    ),
                ));
            }
            for a in s.args.chunks(3) {
                let u0 = number(&a[0], &format!("{keyword}: u0"))?;
                let u1 = number(&a[1], &format!("{keyword}: u1"))?;
                let curve = Self::element_number("curv2", self.curves2.len(), &a[2])?;
                body.curves.push(([u0, u1], curve));
            }
        }
        // `trim` and `hole` are applied (formats/obj/trims.rs); special curves and points are
        // only kept.
        let what = match keyword {
            "trim" | "hole" => None,
            "scrv" => Some("special curve"),
            _ => Some("special point"),
        };
        let on = open.kind.word();
        if let Some(what) = what {
            self.warnings.add(keyword, s.line, || {
                format!("'{keyword}' kept for saving, not applied ({what}; on the {on})")
            });
        }
        if let Some(open) = &mut self.open {
            open.body.push(body);
        }
        Ok(())
    }

    /// `con surf_1 q0_1 q1_1 curv2d_1 surf_2 q0_2 q1_2 curv2d_2`.
    fn con(&mut self, s: &Statement) -> Result<(), ObjError> {
        let a = &s.args;
        if a.len() != 8 {
            return Err(ObjError::new(
                s.line,
                format!(
                    "con takes surf_1 q0_1 q1_1 curv2d_1 surf_2 q0_2 q1_2 curv2d_2, found {} values",
                    a.len()
                ),
            ));
        }
        let side = |k: usize| -> Result<(ElementRef, [f64; 2], ElementRef), ObjError> {
            let a = &a[4 * k..4 * k + 4];
            Ok((
                Self::element_number("surf", self.surfaces.len(), &a[0])?,
                [
                    number(&a[1], &format!("con: q0_{}", k + 1))?,
                    number(&a[2], &format!("con: q1_{}", k + 1))?,
                ],
                Self::element_number("curv2", self.curves2.len(), &a[3])?,
            ))
        };
        let sides = [side(0)?, side(1)?];
        self.cons.push(ConRead {
            line: s.line,
            sides,
        });
        self.warnings.add("con", s.line, || {
            "'con' (surface connectivity) kept for saving, not used".into()
        });
        Ok(())
    }

    /// `ctech` / `stech`: state for the curves (surfaces) that follow.
    fn technique(&mut self, s: &Statement) -> Result<(), ObjError> {
        let surface = s.keyword == "stech";
        let Some((name, values)) = s.args.split_first() else {
            return Err(ObjError::new(
                s.line,
                format!("{} takes a technique and its values", s.keyword),
            ));
        };
        let t = Technique {
            name: name.text.to_string(),
            values: values
                .iter()
                .enumerate()
                .map(|(i, v)| number(v, &format!("{} {}: value {}", s.keyword, name.text, i + 1)))
                .collect::<Result<_, _>>()?,
        };
        t.check(surface).map_err(|e| ObjError::new(s.line, e))?;
        self.warnings.add(s.keyword, s.line, || {
            format!(
                "'{}' kept for saving, not used: sample counts come from '# prespline samples', --samples or the default (docs/obj.md)",
                s.keyword
            )
        });
        if surface {
            self.stech = Some(t);
        } else {
            self.ctech = Some(t);
        }
        Ok(())
    }

    fn end(&mut self, s: &Statement) -> Result<(), ObjError> {
        let Some(open) = self.open.take() else {
            return Err(ObjError::new(
                s.line,
                "end without a curv, curv2 or surf before it",
            ));
        };
        if open.kind == ElementKind::Curve2 {
            // Trims draw with their curves; a curve nothing names is kept silently, like the
            // `scrv` and `sp` statements that name the rest (warned about there).
            let c = Self::curve2(open)?;
            self.curves2.push(c);
            return Ok(());
        }
        let surface = open.surface;
        if let Some(c) = self.check(open)? {
            if let Some(k) = surface {
                self.surfaces[k] = Some(self.done.len());
            }
            self.done.push(c);
        }
        Ok(())
    }

    /// A `curv2` at its `end`: kept as written, so it needs what its `cstype`, `deg` and
    /// `parm u` lines give; its vertex numbers are checked with the others.
    fn curve2(open: Open) -> Result<Curve2Read, ObjError> {
        let line = open.line;
        if open.refs.is_empty() {
            return Err(ObjError::new(line, "curv2 takes parameter vertex numbers"));
        }
        let cstype = open
            .cstype
            .ok_or_else(|| ObjError::new(line, "curv2 without a cstype statement before it"))?;
        let degree = open
            .degrees
            .as_ref()
            .ok_or_else(|| ObjError::new(line, "curv2 without a deg statement before it"))?
            .values[0];
        let [parm, _] = open.parm;
        let (parm, _) =
            parm.ok_or_else(|| ObjError::new(line, "curv2 has no parm u before its end"))?;
        Ok(Curve2Read {
            line,
            cstype,
            degree,
            vertices: open.refs,
            parm,
            body: open.body,
            technique: open.technique,
        })
    }

    fn extension(&mut self, s: &Statement) -> Result<(), ObjError> {
        let values = || {
            s.args
                .iter()
                .map(|t| number(t, &format!("# prespline {}", s.keyword)))
                .collect::<Result<Vec<f64>, _>>()
        };
        match s.keyword {
            "samples" => {
                let counts = s
                    .args
                    .iter()
                    .map(|t| t.text.parse::<usize>().ok().filter(|&m| m >= 2))
                    .collect::<Option<Vec<usize>>>()
                    .filter(|c| (1..=2).contains(&c.len()))
                    .ok_or_else(|| {
                        ObjError::new(
                            s.line,
                            "# prespline samples takes one count (curves) or two (surfaces), each at least 2",
                        )
                    })?;
                let total = counts.iter().fold(1usize, |a, &m| a.saturating_mul(m));
                let max = if counts.len() == 1 {
                    MAX_CURVE_SAMPLES
                } else {
                    MAX_SURFACE_SAMPLES
                };
                if total > max {
                    return Err(ObjError::new(
                        s.line,
                        format!("# prespline samples: {total} samples exceed the limit of {max}"),
                    ));
                }
                self.pending.samples = Some((counts, s.line));
            }
            "color" => {
                let v = values()?;
                if v.len() != 3 || v.iter().any(|c| !(0.0..=1.0).contains(c)) {
                    return Err(ObjError::new(
                        s.line,
                        "# prespline color takes r g b, each in [0, 1]",
                    ));
                }
                self.pending.color = Some(([v[0], v[1], v[2]], s.line));
            }
            other => self.warnings.add(&format!("#{other}"), s.line, || {
                format!("unknown '# prespline {other}' comment ignored")
            }),
        }
        Ok(())
    }

    /// Checks an element at its `end`; `None` for elements that are skipped with a warning.
    fn check(&mut self, open: Open) -> Result<Option<Checked>, ObjError> {
        let word = open.kind.word();
        let line = open.line;
        let cs = open.cstype.ok_or_else(|| {
            ObjError::new(line, format!("{word} without a cstype statement before it"))
        })?;
        let basis = match cs.kind {
            CsKind::Supported(b) => b,
            CsKind::Unsupported(name) => {
                self.warnings.add(&format!("cstype {name}"), line, || {
                    format!(
                        "{word} skipped: cstype {name} is not supported (bezier and bspline are, rational or not)"
                    )
                });
                return Ok(None);
            }
        };
        let degrees = open.degrees.as_ref().ok_or_else(|| {
            ObjError::new(line, format!("{word} without a deg statement before it"))
        })?;
        let surface = open.kind == ElementKind::Surface;
        if surface && degrees.values.len() != 2 {
            return Err(ObjError::new(
                line,
                format!(
                    "surf needs two degrees, but the deg statement at line {} gives one",
                    degrees.line
                ),
            ));
        }
        let ndirs = if surface { 2 } else { 1 };
        let dirs = check::directions(
            &check::Body {
                keyword: word,
                line,
                basis,
                degrees: &degrees.values,
                ranges: &open.ranges,
                parm: &open.parm[..ndirs],
                vertices: open.refs.len(),
            },
            &mut self.warnings,
        )?;
        let samples = match open.pending.samples {
            Some((s, _)) if s.len() == ndirs => Some(s),
            Some((s, l)) => {
                return Err(ObjError::new(
                    l,
                    format!(
                        "# prespline samples gives {} count(s), but the {word} at line {line} needs {ndirs}",
                        s.len()
                    ),
                ));
            }
            None => None,
        };
        Ok(Some(Checked {
            element: FreeForm {
                basis,
                rational: cs.rational,
                dirs,
                points: Vec::new(),
                weights: Vec::new(),
                name: open.name,
                samples,
                color: open.pending.color.map(|(c, _)| c),
                line,
                carried: ObjKept {
                    technique: open.technique,
                    ..ObjKept::default()
                },
            },
            refs: open.refs,
            body: open.body,
        }))
    }

    fn finish(mut self) -> Result<Parsed, ObjError> {
        if let Some(open) = &self.open {
            return Err(ObjError::new(
                open.line,
                format!("{} has no end before the end of the file", open.kind.word()),
            ));
        }
        let counts = self.counts;
        let check = |r: &VertexRef| -> Result<(), ObjError> {
            let count = counts[r.kind as usize];
            if r.index >= count {
                let what = r.kind.word();
                return Err(ObjError::new(
                    r.line,
                    format!(
                        "{what} {} does not exist: the file has {count} {what} statement(s)",
                        r.index.saturating_add(1)
                    ),
                ));
            }
            Ok(())
        };
        self.refs.iter().try_for_each(check)?;
        self.check_kept(check)?;
        let mut elements = Vec::with_capacity(self.done.len());
        let mut bodies = Vec::with_capacity(self.done.len());
        for mut c in std::mem::take(&mut self.done) {
            c.refs.iter().try_for_each(check)?;
            bodies.push(std::mem::take(&mut c.body));
            elements.push(self.resolve_points(c)?);
        }
        let mut used = HashSet::new();
        for e in &mut elements {
            e.name = Some(super::unique_name(e, &mut used));
        }
        self.keep(&mut elements, &bodies);
        if let Some((_, line)) = self.pending.samples {
            self.warnings.add("#samples", line, || {
                "'# prespline samples' is not followed by a curv or surf; ignored".into()
            });
        }
        if let Some((_, line)) = self.pending.color {
            self.warnings.add("#color", line, || {
                "'# prespline color' is not followed by a curv or surf; ignored".into()
            });
        }
        Ok(Parsed {
            elements,
            warnings: self.warnings.into_list(),
        })
    }

    /// Every number in the kept statements names something in the file.
    fn check_kept(
        &self,
        vertex: impl Fn(&VertexRef) -> Result<(), ObjError>,
    ) -> Result<(), ObjError> {
        let element = |what: &str, r: &ElementRef, count: usize| {
            if r.index >= count {
                return Err(ObjError::new(
                    r.line,
                    format!(
                        "{what} {} does not exist: the file has {count} {what} element(s)",
                        r.index.saturating_add(1)
                    ),
                ));
            }
            Ok(())
        };
        let curves = self.curves2.len();
        let bodies = self.done.iter().flat_map(|c| &c.body);
        for b in bodies.chain(self.curves2.iter().flat_map(|c| &c.body)) {
            b.points.iter().try_for_each(&vertex)?;
            for (_, r) in &b.curves {
                element("curv2", r, curves)?;
            }
        }
        for c in &self.curves2 {
            c.vertices.iter().try_for_each(&vertex)?;
        }
        for con in &self.cons {
            for (surface, _, curve) in &con.sides {
                element("surf", surface, self.surfaces.len())?;
                element("curv2", curve, curves)?;
            }
        }
        Ok(())
    }

    /// Gives every element what belongs with it: the `curv2` elements its body statements and
    /// `con` statements name (and those nothing names, with the element that follows them),
    /// the parameter vertices those use, and the `con` statements of which it is the first
    /// surface read — all with local numbers.
    fn keep(&mut self, elements: &mut [FreeForm], bodies: &[Vec<BodyRead>]) {
        if elements.is_empty() {
            return;
        }
        let mut needs: Vec<BTreeSet<usize>> = bodies.iter().map(|b| curves_named(b)).collect();
        let links = self.links(&mut needs);
        for set in &mut needs {
            self.close_over_curves(set);
        }
        let named: HashSet<usize> = needs.iter().flatten().copied().collect();
        for (k, c) in self.curves2.iter().enumerate() {
            if !named.contains(&k) {
                let i = elements
                    .iter()
                    .position(|e| e.line > c.line)
                    .unwrap_or(elements.len() - 1);
                needs[i].insert(k);
            }
        }
        let locals: Vec<Local> = needs
            .into_iter()
            .zip(bodies)
            .map(|(c, b)| self.local(c, b))
            .collect();
        for (i, e) in elements.iter_mut().enumerate() {
            self.fill(&mut e.carried, &bodies[i], &locals[i]);
        }
        for Link {
            carrier: a,
            here,
            other: b,
            there,
        } in links
        {
            let connection = Connection {
                curve: CurveRef {
                    range: here.0,
                    curve: locals[a].curve(here.1),
                },
                surface: elements[b].name.clone().unwrap_or_default(),
                surface_curve: CurveRef {
                    range: there.0,
                    curve: locals[b].curve(there.1),
                },
            };
            elements[a].carried.connections.push(connection);
        }
    }

    /// The `con` statements as links between elements, each edge's `curv2` added to the needs
    /// of its surface; a `con` naming a surface that was skipped is dropped, with a warning.
    fn links(&mut self, needs: &mut [BTreeSet<usize>]) -> Vec<Link> {
        let mut links = Vec::new();
        for con in &self.cons {
            let [(s1, q1, c1), (s2, q2, c2)] = con.sides;
            match (self.surfaces[s1.index], self.surfaces[s2.index]) {
                (Some(a), Some(b)) => {
                    needs[a].insert(c1.index);
                    needs[b].insert(c2.index);
                    links.push(Link {
                        carrier: a,
                        here: (q1, c1.index),
                        other: b,
                        there: (q2, c2.index),
                    });
                }
                (a, _) => {
                    let skipped = if a.is_none() { s1 } else { s2 };
                    self.warnings.add("con dropped", con.line, || {
                        format!(
                            "'con' dropped: it joins surf {}, which was skipped",
                            skipped.index + 1
                        )
                    });
                }
            }
        }
        links
    }

    /// Adds the `curv2` elements named in the bodies of those already in `set`.
    fn close_over_curves(&self, set: &mut BTreeSet<usize>) {
        let mut todo: Vec<usize> = set.iter().copied().collect();
        while let Some(k) = todo.pop() {
            for c in curves_named(&self.curves2[k].body) {
                if set.insert(c) {
                    todo.push(c);
                }
            }
        }
    }

    /// Local numbers for an element's `curv2` elements (file order) and the parameter
    /// vertices its body and those curves use (file order).
    fn local(&self, curves: BTreeSet<usize>, body: &[BodyRead]) -> Local {
        let mut vertices: BTreeSet<usize> = points_named(body).collect();
        for &k in &curves {
            let c = &self.curves2[k];
            vertices.extend(c.vertices.iter().map(|r| r.index));
            vertices.extend(points_named(&c.body));
        }
        Local::new(curves, vertices)
    }

    /// Writes the kept data of one element with its local numbers (connections come after).
    fn fill(&self, carried: &mut ObjKept, body: &[BodyRead], local: &Local) {
        carried.parameter_vertices = local
            .vertices
            .iter()
            .map(|&g| self.params[g].clone())
            .collect();
        carried.curves2 = local
            .curves
            .iter()
            .map(|&g| {
                let c = &self.curves2[g];
                Curve2 {
                    rational: c.cstype.rational,
                    basis: c.cstype.kind.word().to_string(),
                    degree: c.degree,
                    vertices: c.vertices.iter().map(|r| local.vertex(r.index)).collect(),
                    parm: c.parm.clone(),
                    body: local.body(&c.body),
                    technique: c.technique.clone(),
                }
            })
            .collect();
        carried.body = local.body(body);
    }

    fn resolve_points(&mut self, c: Checked) -> Result<FreeForm, ObjError> {
        let mut e = c.element;
        for r in &c.refs {
            let v = self.vertices[r.index];
            let w = match (e.rational, v.weight) {
                (true, Some(w)) if w <= 0.0 => {
                    return Err(ObjError::new(
                        v.line,
                        format!(
                            "v has weight {w}, but the rational {} at line {} needs positive weights",
                            e.keyword(),
                            e.line
                        ),
                    ));
                }
                (true, w) => w.unwrap_or(1.0),
                (false, Some(w)) if w != 1.0 => {
                    let line = v.line;
                    self.warnings.add("non-rational weight", line, || {
                        format!(
                            "weight {w} ignored: the {} at line {} is not rational (cstype without rat)",
                            e.keyword(),
                            e.line
                        )
                    });
                    1.0
                }
                (false, _) => 1.0,
            };
            e.points.push(v.point);
            e.weights.push(w);
        }
        Ok(e)
    }
}

/// A `con` between two elements read: the first surface (which keeps it) and the other, each
/// with its edge (q0 q1 and the file-wide `curv2` number).
struct Link {
    carrier: usize,
    here: ([f64; 2], usize),
    other: usize,
    there: ([f64; 2], usize),
}

/// An element's numbering of what it keeps: local index → file-wide index and back.
struct Local {
    curves: Vec<usize>,
    curve_of: HashMap<usize, usize>,
    vertices: Vec<usize>,
    vertex_of: HashMap<usize, usize>,
}

impl Local {
    fn new(curves: BTreeSet<usize>, vertices: BTreeSet<usize>) -> Self {
        let invert = |v: &[usize]| v.iter().enumerate().map(|(i, &g)| (g, i)).collect();
        let curves: Vec<usize> = curves.into_iter().collect();
        let vertices: Vec<usize> = vertices.into_iter().collect();
        Self {
            curve_of: invert(&curves),
            vertex_of: invert(&vertices),
            curves,
            vertices,
        }
    }

    /// Every file-wide number given to [`Local::new`] has a local one.
    fn curve(&self, global: usize) -> usize {
        self.curve_of[&global]
    }

    fn vertex(&self, global: usize) -> usize {
        self.vertex_of[&global]
    }

    fn body(&self, body: &[BodyRead]) -> Vec<Body> {
        body.iter()
            .filter_map(|b| {
                let curves = b
                    .curves
                    .iter()
                    .map(|&(range, r)| CurveRef {
                        range,
                        curve: self.curve(r.index),
                    })
                    .collect();
                let points = b.points.iter().map(|r| self.vertex(r.index)).collect();
                Body::new(b.keyword, curves, points)
            })
            .collect()
    }
}

/// The `curv2` elements a body names (file-wide numbers).
fn curves_named(body: &[BodyRead]) -> BTreeSet<usize> {
    body.iter()
        .flat_map(|b| b.curves.iter().map(|(_, r)| r.index))
        .collect()
}

/// The parameter vertices a body's `sp` statements name (file-wide numbers).
fn points_named(body: &[BodyRead]) -> impl Iterator<Item = usize> + '_ {
    body.iter().flat_map(|b| b.points.iter().map(|r| r.index))
}

/// A finite number; `what` names it in the message.
fn number(t: &Token, what: &str) -> Result<f64, ObjError> {
    match t.text.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(ObjError::new(
            t.line,
            format!("{what} is '{}', not a finite number", t.text),
        )),
        Err(_) => Err(ObjError::new(
            t.line,
            format!("{what}: '{}' is not a number", t.text),
        )),
    }
}

fn join(tokens: &[Token]) -> String {
    tokens.iter().map(|t| t.text).collect::<Vec<_>>().join(" ")
}
