//! Statements → [`FreeForm`] elements. The reader keeps the OBJ state (`cstype`, `deg`, the
//! current name) and checks every element when its `end` arrives; vertex numbers are checked
//! once the whole file is read, since a positive number may name a vertex written later.

use super::check;
use super::lex::{Statement, Token};
use super::model::{Basis, FreeForm};
use super::{ObjError, ObjWarning, Warnings};
use crate::scene::{MAX_CURVE_SAMPLES, MAX_DEGREE, MAX_SURFACE_SAMPLES};
use glam::DVec3;

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
}

impl VertexKind {
    fn word(self) -> &'static str {
        match self {
            VertexKind::Geometric => "v",
            VertexKind::Texture => "vt",
            VertexKind::Normal => "vn",
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

/// An element between its `curv`/`surf` and its `end`.
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
}

/// A checked element whose control vertices are resolved at the end of the file.
#[derive(Debug, Clone)]
struct Checked {
    element: FreeForm,
    refs: Vec<VertexRef>,
}

#[derive(Debug, Default)]
struct Reader {
    vertices: Vec<Vertex>,
    counts: [usize; 3],
    refs: Vec<VertexRef>,
    cstype: Option<CsType>,
    degrees: Option<Degrees>,
    name: Option<String>,
    pending: Pending,
    open: Option<Open>,
    done: Vec<Checked>,
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
            "trim" | "hole" | "scrv" | "sp" => self.body_ignored(s),
            "end" => self.end(s),
            "o" | "g" => {
                let name = join(&s.args);
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
            "con" => {
                self.warnings.add("con", s.line, || {
                    "'con' (surface connectivity) ignored".into()
                });
                Ok(())
            }
            "bmat" | "step" => {
                self.warnings.add(s.keyword, s.line, || {
                    format!(
                        "'{}' ignored: it belongs to cstype bmatrix, cardinal and taylor, which are not supported",
                        s.keyword
                    )
                });
                Ok(())
            }
            "ctech" | "stech" => {
                self.warnings.add(s.keyword, s.line, || {
                    format!(
                        "'{}' ignored: sample counts come from '# prespline samples', --samples or the default (docs/obj.md)",
                        s.keyword
                    )
                });
                Ok(())
            }
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
        for (i, t) in s.args.iter().enumerate() {
            number(t, &format!("{}: value {}", s.keyword, i + 1))?;
        }
        match s.keyword {
            "vt" => self.counts[1] += 1,
            "vn" => self.counts[2] += 1,
            _ => {} // vp: only trimming curves and special points use it; both are skipped
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
        if kind != ElementKind::Curve2 {
            for t in &s.args[2 * nranges..] {
                self.element_ref(kind, t, &mut refs)?;
            }
        }
        let pending = std::mem::take(&mut self.pending);
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

    fn body_ignored(&mut self, s: &Statement) -> Result<(), ObjError> {
        let Some(open) = &self.open else {
            return Err(ObjError::new(
                s.line,
                format!("{} outside a curv or surf body", s.keyword),
            ));
        };
        let what = match s.keyword {
            "trim" => "outer trimming loop: the surface is imported untrimmed",
            "hole" => "trimming hole: the surface is imported without it",
            "scrv" => "special curve",
            _ => "special point",
        };
        let on = open.kind.word();
        self.warnings.add(s.keyword, s.line, || {
            format!("'{}' ignored ({what}; on the {on})", s.keyword)
        });
        Ok(())
    }

    fn end(&mut self, s: &Statement) -> Result<(), ObjError> {
        let Some(open) = self.open.take() else {
            return Err(ObjError::new(
                s.line,
                "end without a curv, curv2 or surf before it",
            ));
        };
        if let Some(c) = self.check(open)? {
            self.done.push(c);
        }
        Ok(())
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
        if open.kind == ElementKind::Curve2 {
            self.warnings.add("curv2", line, || {
                "'curv2' (trimming curve) ignored: trimming is not supported".into()
            });
            return Ok(None);
        }
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
            },
            refs: open.refs,
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
        let mut elements = Vec::with_capacity(self.done.len());
        for c in std::mem::take(&mut self.done) {
            c.refs.iter().try_for_each(check)?;
            elements.push(self.resolve_points(c)?);
        }
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
