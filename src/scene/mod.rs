//! Scenes: named objects with sample counts and display style, the JSON scene file format
//! (DESIGN.md contract), edits, and the built-in demo.

pub mod demo;
pub mod edit;
mod json;
mod parse;
mod write;

pub use edit::{Edit, EditOp, Index2};
pub use parse::parse_scene;
pub use write::scene_to_json;

use crate::geom::{BSplineCurve, ErbsCurve, ErbsSurface, TensorSurface};
use std::path::Path;

/// Largest polynomial degree accepted from files (per direction). Evaluation works for any
/// degree; this bounds memory (pre-evaluated matrices grow with (d+1)²) and rejects nonsense.
pub const MAX_DEGREE: usize = 64;
/// Largest sample count per curve.
pub const MAX_CURVE_SAMPLES: usize = 10_000_000;
/// Largest sample count of a surface (mu · mv).
pub const MAX_SURFACE_SAMPLES: usize = 1 << 24;

/// Anything wrong with a scene or edit file, as one line naming the object, field and index.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SceneError(pub String);

/// A whole scene: objects in file order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    pub objects: Vec<SceneObject>,
}

/// One named object.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    pub name: String,
    pub shape: Shape,
    pub samples: Samples,
    /// Optional display colour (linear RGB in [0, 1]); the viewer picks one per object otherwise.
    pub color: Option<[f64; 3]>,
}

/// The geometry of an object. Bézier objects are kept as B-splines with Bézier knot vectors so
/// that one pre-evaluation path serves both; the variant remembers the file type.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    BezierCurve(BSplineCurve),
    BSplineCurve(BSplineCurve),
    ErbsCurve(ErbsCurve),
    BezierSurface(TensorSurface),
    BSplineSurface(TensorSurface),
    ErbsSurface(ErbsSurface),
}

/// Sample counts: m for curves, [mu, mv] for surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Samples {
    Curve(usize),
    Surface([usize; 2]),
}

impl Shape {
    /// The scene-file `type` string.
    pub fn type_name(&self) -> &'static str {
        match self {
            Shape::BezierCurve(_) => "bezier_curve",
            Shape::BSplineCurve(_) => "bspline_curve",
            Shape::ErbsCurve(_) => "erbs_curve",
            Shape::BezierSurface(_) => "bezier_surface",
            Shape::BSplineSurface(_) => "bspline_surface",
            Shape::ErbsSurface(_) => "erbs_surface",
        }
    }

    pub fn is_surface(&self) -> bool {
        matches!(
            self,
            Shape::BezierSurface(_) | Shape::BSplineSurface(_) | Shape::ErbsSurface(_)
        )
    }

    /// Parameter domain per direction (one entry for curves).
    pub fn domain(&self) -> Vec<(f64, f64)> {
        match self {
            Shape::BezierCurve(c) | Shape::BSplineCurve(c) => vec![c.domain()],
            Shape::ErbsCurve(c) => vec![c.domain()],
            Shape::BezierSurface(s) | Shape::BSplineSurface(s) => s.domain().to_vec(),
            Shape::ErbsSurface(s) => s.domain().to_vec(),
        }
    }
}

impl Scene {
    /// Reads and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError(format!("cannot read {}: {e}", path.display())))?;
        parse_scene(&text)
    }

    /// Writes the scene file atomically and durably (see [`write_durably`]), so neither a
    /// failed save nor a crash or power loss right after it destroys the previous file.
    pub fn save(&self, path: &Path) -> Result<(), SceneError> {
        write_durably(path, scene_to_json(self).as_bytes())
            .map_err(|e| SceneError(format!("cannot write {}: {e}", path.display())))
    }

    pub fn find(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }
}

/// Replaces `path` with `bytes` atomically and durably: the bytes go to a temporary file in the
/// same directory, which is flushed to disk (fsync) before it is renamed over `path`, and the
/// directory is flushed after the rename. Readers see the old file or the new one, never a
/// part; after a crash the rename is not there without the data it points to.
pub fn write_durably(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file path"))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let written = std::fs::File::create(&tmp).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()
    });
    if let Err(e) = written.and_then(|()| std::fs::rename(&tmp, path)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::File::open(dir).and_then(|d| d.sync_all())
}
