//! The output of the CAD readers: trimmed NURBS faces in millimetres, ready to become prespline
//! scene objects, one set of types for STEP and IGES.
//!
//! For STEP: `name` is the product name + `#` + the ADVANCED_FACE's id; `surface_type` the face
//! geometry's entity name (`PLANE`, …). For IGES: `name` is the file stem (or the Global
//! section's product id) + `#` + the DE number of the face entity (144, 143, 510 or the surface
//! itself); `surface_type` is `entity 128`, `entity 120`, …; `outer` comes from the loops'
//! nesting (IGES 143 does not say which boundary is outer). Instances of one face after the
//! first (assemblies, subfigures) get `@2`, `@3`, … appended.

use crate::geom::analytic::NurbsSurface;

/// A whole CAD file mapped.
#[derive(Clone, Debug, PartialEq)]
pub struct CadModel {
    /// Every face instance, in product-structure order.
    pub faces: Vec<CadFace>,
    /// What was read but is not drawn: one entry per entity type (and reason), with a count.
    pub skipped: Vec<Skipped>,
    /// One line each, naming the line and `#id` (one per skipped type, and other notes).
    pub warnings: Vec<String>,
    /// Always `"mm"`: lengths are converted.
    pub unit: String,
}

/// Entities of one type that were read but not drawn.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Skipped {
    /// The entity type, as in the file (`OFFSET_SURFACE`, `GEOMETRIC_CURVE_SET`).
    pub what: String,
    /// How many (face instances count once per assembly instance).
    pub count: usize,
    /// Why, in a few words.
    pub reason: String,
}

/// One face instance: an exact rational B-spline surface and its trim loops.
#[derive(Clone, Debug, PartialEq)]
pub struct CadFace {
    /// Product name + `#` + the face's entity id (`bracket#1234`); a second instance of the
    /// same face in an assembly gets `@2`, a third `@3`, … appended, so names are unique.
    pub name: String,
    /// The face geometry's entity type as in the file (`PLANE`, `CYLINDRICAL_SURFACE`, …).
    pub surface_type: String,
    /// In mm, placed by the assembly transformations.
    pub surface: NurbsSurface,
    /// In the surface's own parameter space.
    pub loops: Vec<CadLoop>,
    /// Linear RGB in [0, 1] of the innermost styled item (face, shell, solid, shape).
    pub color: Option<[f64; 3]>,
    /// The face's outward normal is `−(S_u × S_v)` (ADVANCED_FACE same_sense = .F., oriented
    /// shells and faces, a mirroring placement).
    pub reversed: bool,
}

/// One closed trim loop.
#[derive(Clone, Debug, PartialEq)]
pub struct CadLoop {
    /// The file's FACE_OUTER_BOUND (or, without one, the loop with the largest box).
    pub outer: bool,
    /// Consecutive pieces: each ends where the next starts, the last where the first starts.
    pub pieces: Vec<CadPiece>,
}

/// One piece of a loop: a 2D curve over a parameter range.
#[derive(Clone, Debug, PartialEq)]
pub struct CadPiece {
    pub curve: CadCurve2,
    /// `range.0 > range.1`: traversed backwards. A polyline's parameter is the vertex index.
    pub range: (f64, f64),
}

/// A curve in a surface's parameter space.
#[derive(Clone, Debug, PartialEq)]
pub enum CadCurve2 {
    /// Straight segments through the points (parameter `i` at point `i`).
    Polyline(Vec<[f64; 2]>),
    /// A clamped B-spline (rational with `weights`) whose domain is exactly the piece's range.
    Nurbs {
        degree: usize,
        knots: Vec<f64>,
        points: Vec<[f64; 2]>,
        weights: Option<Vec<f64>>,
    },
}
