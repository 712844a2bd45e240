//! Scenes: named objects with sample counts and display style, the JSON scene file format
//! (DESIGN.md contract), edits, and the built-in demo.

pub mod demo;
pub mod edit;
mod json;
pub mod obj;
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

    /// Writes the scene file atomically (temporary file + rename), so a failed save never
    /// destroys the previous file.
    pub fn save(&self, path: &Path) -> Result<(), SceneError> {
        let text = scene_to_json(self);
        let tmp = path.with_extension("json.tmp");
        std::fs::write(&tmp, text)
            .and_then(|()| std::fs::rename(&tmp, path))
            .map_err(|e| SceneError(format!("cannot write {}: {e}", path.display())))
    }

    pub fn find(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }
}
