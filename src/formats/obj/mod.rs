//! Wavefront OBJ free-form geometry in and out (`cstype`, `deg`, `curv`, `surf`, `parm`, `end`
//! with `v` control vertices), the exchange format Rhino, Maya and Ayam write for NURBS and
//! Bézier geometry. Reading goes text → statements (`lex`) → free-form elements as written
//! (`read`, [`model::FreeForm`]) → scene objects (`map`); writing goes the other way.
//! What a file holds that prespline does not use (trims, `curv2`, `vp`, `con`, techniques) is
//! kept with its scene object ([`kept::ObjKept`]) and written back. Everything a user can
//! rely on — which constructs map, how exactly, what is kept, what is refused — is in
//! docs/obj.md.

mod check;
mod erbs;
pub mod kept;
mod lex;
mod map;
pub mod model;
mod read;
mod trims;
mod write;

pub use map::{default_curve_samples, default_surface_samples};

use super::context::{FileFormat, FormatError, Import, LoadContext, Located, Written};
use crate::scene::{Scene, SceneError};
use model::FreeForm;
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// A problem with an OBJ file, at a (1-based) line.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct ObjError {
    pub line: usize,
    pub message: String,
}

impl ObjError {
    pub(crate) fn new(line: usize, message: impl Into<String>) -> Self {
        Self {
            line,
            message: message.into(),
        }
    }

    /// `FILE:LINE: message`, the form compilers use, so editors can jump to it.
    #[must_use]
    pub fn in_file(&self, path: &Path) -> String {
        format!("{}:{}: {}", path.display(), self.line, self.message)
    }
}

/// Something in an OBJ file that was read past (polygons, trims, unsupported types, …).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjWarning {
    pub line: usize,
    pub message: String,
}

impl ObjWarning {
    /// `FILE:LINE: warning: message`.
    #[must_use]
    pub fn in_file(&self, path: &Path) -> String {
        format!(
            "{}:{}: warning: {}",
            path.display(),
            self.line,
            self.message
        )
    }
}

/// A scene read from OBJ and what was ignored on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjImport {
    pub scene: Scene,
    pub warnings: Vec<ObjWarning>,
}

/// The free-form elements of OBJ text exactly as written (before mapping to scene objects).
pub fn read_elements(text: &str) -> Result<(Vec<FreeForm>, Vec<ObjWarning>), ObjError> {
    let parsed = read::read(&lex::statements(text))?;
    Ok((parsed.elements, parsed.warnings))
}

/// Parses OBJ text into a scene.
pub fn parse_obj(text: &str) -> Result<ObjImport, ObjError> {
    let (elements, warnings) = read_elements(text)?;
    if elements.is_empty() {
        // Say why, at the first thing that was read past (a skipped element, polygons, …).
        let (line, why) = warnings
            .first()
            .map_or((1, String::new()), |w| (w.line, format!("; {}", w.message)));
        return Err(ObjError::new(
            line,
            format!(
                "no free-form curve or surface (curv/surf with cstype bezier or bspline) to read{why}"
            ),
        ));
    }
    // The reader made the names unique (connections name the surfaces they join).
    let objects = elements
        .iter()
        .map(|e| map::element_to_object(e, e.name.clone().unwrap_or_default()))
        .collect::<Result<_, _>>()?;
    Ok(ObjImport {
        scene: Scene { objects },
        warnings,
    })
}

/// Parses file bytes (UTF-8, with the line of the first bad byte named otherwise).
pub fn parse_obj_bytes(bytes: &[u8]) -> Result<ObjImport, ObjError> {
    parse_obj(lex::decode(bytes)?)
}

/// OBJ text and what it could not hold.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjText {
    pub text: String,
    /// One entry per kept statement that had to be left out (a `con` whose other surface is no
    /// longer in the scene, …), naming the object; empty when everything was written.
    pub dropped: Vec<String>,
}

/// The scene as OBJ text with what had to be left out, or the first object that has no exact
/// OBJ form.
pub fn write_obj(scene: &Scene) -> Result<ObjText, SceneError> {
    let elements = scene
        .objects
        .iter()
        .map(map::object_to_element)
        .collect::<Result<Vec<_>, _>>()?;
    let (text, dropped) = write::write(&elements);
    Ok(ObjText { text, dropped })
}

/// The scene as OBJ text (see [`write_obj`], which also says what had to be left out).
pub fn scene_to_obj(scene: &Scene) -> Result<String, SceneError> {
    write_obj(scene).map(|o| o.text)
}

/// Reads an OBJ file; errors read `FILE:LINE: message`.
pub fn load_obj(path: &Path) -> Result<ObjImport, SceneError> {
    let bytes = std::fs::read(path)
        .map_err(|e| SceneError(format!("cannot read {}: {e}", path.display())))?;
    parse_obj_bytes(&bytes).map_err(|e| SceneError(e.in_file(path)))
}

/// The Wavefront OBJ format.
#[derive(Debug, Clone, Copy)]
pub struct Obj;

impl FileFormat for Obj {
    fn name(&self) -> &'static str {
        "Wavefront OBJ"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["obj"]
    }

    fn read(&self, bytes: &[u8], _ctx: &LoadContext<'_>) -> Result<Import, FormatError> {
        let import = parse_obj_bytes(bytes).map_err(|e| FormatError::at_line(e.line, e.message))?;
        Ok(Import {
            scene: import.scene,
            warnings: import
                .warnings
                .into_iter()
                .map(|w| Located {
                    line: Some(w.line),
                    message: format!("warning: {}", w.message),
                })
                .collect(),
            skipped: Vec::new(),
            unit: None,
        })
    }

    fn write(&self, scene: &Scene) -> Result<Written, FormatError> {
        let out = write_obj(scene)?;
        Ok(Written {
            bytes: out.text.into_bytes(),
            dropped: out.dropped,
        })
    }

    fn writes(&self) -> bool {
        true
    }

    fn kept_key(&self) -> Option<&'static str> {
        Some("obj")
    }

    fn read_kept(
        &self,
        at: &crate::fields::At,
        v: &serde_json::Value,
        surface: bool,
    ) -> Result<Box<dyn crate::scene::Kept>, SceneError> {
        kept::from_json(at, v, surface).map(|k| Box::new(k) as Box<dyn crate::scene::Kept>)
    }
}

/// The element's `o`/`g` name (or "curve"/"surface"), made unique with ".2", ".3", ….
pub(crate) fn unique_name(e: &FreeForm, used: &mut HashSet<String>) -> String {
    let base = e
        .name
        .clone()
        .unwrap_or_else(|| if e.is_surface() { "surface" } else { "curve" }.to_string());
    let mut name = base.clone();
    let mut k = 2;
    while used.contains(&name) {
        name = format!("{base}.{k}");
        k += 1;
    }
    used.insert(name.clone());
    name
}

/// Warnings grouped by kind: one line per kind, at its first occurrence, with a count.
#[derive(Debug, Default)]
struct Warnings {
    kinds: Vec<Warned>,
    /// Kind key → index into `kinds`.
    index: HashMap<String, usize>,
}

/// One kind of warning.
#[derive(Debug)]
struct Warned {
    /// Line of the first occurrence.
    line: usize,
    count: usize,
    message: String,
}

impl Warnings {
    /// Counts an occurrence of `key`; the message is made once, for the first.
    fn add(&mut self, key: &str, line: usize, message: impl FnOnce() -> String) {
        match self.index.get(key) {
            Some(&i) => self.kinds[i].count += 1,
            None => {
                self.index.insert(key.to_string(), self.kinds.len());
                self.kinds.push(Warned {
                    line,
                    count: 1,
                    message: message(),
                });
            }
        }
    }

    fn into_list(self) -> Vec<ObjWarning> {
        let mut out: Vec<ObjWarning> = self
            .kinds
            .into_iter()
            .map(|w| ObjWarning {
                line: w.line,
                message: if w.count > 1 {
                    format!("{} ({} times, first here)", w.message, w.count)
                } else {
                    w.message
                },
            })
            .collect();
        out.sort_by_key(|w| w.line);
        out
    }
}
