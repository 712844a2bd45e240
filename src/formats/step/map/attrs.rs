//! Typed access to the entities the mapping reads, on top of the STEP reader's views.
//!
//! Two things the reader leaves to its caller are done here once:
//! - *inherited attributes*: a simple instance `B_SPLINE_SURFACE_WITH_KNOTS(name, …)` lists the
//!   attributes of every supertype first, while a complex instance
//!   `(B_SPLINE_SURFACE(…) B_SPLINE_SURFACE_WITH_KNOTS(…) REPRESENTATION_ITEM('') …)` gives each
//!   entity its own record (ISO 10303-21 §11.2.5.2). [`part`] finds an entity's own attributes
//!   in both forms;
//! - the ISO 10303-42 placement entities (CARTESIAN_POINT, DIRECTION, VECTOR,
//!   AXIS2_PLACEMENT_3D/2D, AXIS1_PLACEMENT), read into `glam` values.
//!
//! Every error is one line naming the line, `#id` and entity (the reader's `StepError` text).

use crate::formats::step::{EntityRef, ParamRef, RecordRef, StepError};
use crate::geom::analytic::Frame;
use glam::{DVec2, DVec3};

/// Results of the mapping.
pub(crate) type Res<T> = Result<T, Error>;

/// Why something could not be mapped; `text` is one line, `line N: #id = ENTITY: …`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Error {
    pub text: String,
    pub kind: Kind,
    /// For a skipped face: where (`line N: #id = TYPE`) and why, apart.
    pub parts: Option<(String, String)>,
}

/// What an [`Error`] means for the file.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Kind {
    /// The file breaks the format or the schema (a dangling or mistyped reference, a zero
    /// radius): reading fails with this line.
    Malformed,
    /// A valid entity the mapping does not draw (its type is given): the face that needs it is
    /// reported in `skipped`.
    Unsupported(String),
    /// The geometry could not be mapped within tolerance (a loop that does not close): the face
    /// is reported in `skipped`.
    Geometry,
}

/// The reader's error as a malformed-file error.
#[must_use]
pub(crate) fn msg(e: StepError) -> Error {
    Error {
        text: e.to_string(),
        kind: Kind::Malformed,
        parts: None,
    }
}

/// An invalid entity found by the mapping (a zero radius, a knot vector that decreases).
#[must_use]
pub(crate) fn bad(e: &EntityRef<'_>, message: impl Into<String>) -> Error {
    Error {
        text: e.invalid(message).to_string(),
        kind: Kind::Malformed,
        parts: None,
    }
}

/// A valid entity of a type the mapping does not draw.
#[must_use]
pub(crate) fn unsupported(e: &EntityRef<'_>, reason: impl Into<String>) -> Error {
    skip(e, reason.into(), Kind::Unsupported(e.name().to_owned()))
}

/// An error that skips a face, with its place and reason kept apart.
#[must_use]
fn skip(e: &EntityRef<'_>, why: String, kind: Kind) -> Error {
    let place = format!("line {}: #{} = {}", e.line(), e.id(), e.type_names());
    Error {
        text: format!("{place}: {why}"),
        kind,
        parts: Some((place, why)),
    }
}

/// A geometric failure while mapping `e` (the face is skipped, the file is still read).
#[must_use]
pub(crate) fn failed(e: &EntityRef<'_>, message: impl Into<String>) -> Error {
    skip(e, message.into(), Kind::Geometry)
}

/// One entity's own attributes, wherever they sit (see the module doc).
#[derive(Clone, Copy)]
pub(crate) struct Part<'a> {
    rec: RecordRef<'a>,
    offset: usize,
}

impl<'a> Part<'a> {
    /// Own attribute `i` (0-based), named `name` in error messages.
    pub(crate) fn p(&self, i: usize, name: &'static str) -> Res<ParamRef<'a>> {
        self.rec.param(self.offset + i, name).map_err(msg)
    }
}

/// The attributes of entity type `record` within `e`: in a complex instance its own record; in
/// a simple instance (of `record` or of a subtype) the one record, after the `inherited`
/// attributes of the supertypes.
pub(crate) fn part<'a>(e: EntityRef<'a>, record: &str, inherited: usize) -> Res<Part<'a>> {
    if e.is_complex() {
        let rec = e.record(record).map_err(msg)?;
        return Ok(Part { rec, offset: 0 });
    }
    let rec = e
        .records()
        .next()
        .ok_or_else(|| bad(&e, "instance has no record"))?;
    Ok(Part {
        rec,
        offset: inherited,
    })
}

/// Short forms of the reader's accessors with the error turned into the one-line message.
pub(crate) trait P<'a> {
    fn ent(&self) -> Res<EntityRef<'a>>;
    fn f(&self) -> Res<f64>;
    fn flag(&self) -> Res<bool>;
    fn text(&self) -> Res<&'a str>;
    fn enm(&self) -> Res<&'a str>;
    fn integer(&self) -> Res<i64>;
    fn ents(&self) -> Res<Vec<EntityRef<'a>>>;
    fn nums(&self) -> Res<Vec<f64>>;
}

impl<'a> P<'a> for ParamRef<'a> {
    fn ent(&self) -> Res<EntityRef<'a>> {
        self.entity().map_err(msg)
    }
    fn f(&self) -> Res<f64> {
        let x = self.real().map_err(msg)?;
        if x.is_finite() {
            Ok(x)
        } else {
            Err(msg(self.invalid("is not a finite number")))
        }
    }
    fn flag(&self) -> Res<bool> {
        self.boolean().map_err(msg)
    }
    fn text(&self) -> Res<&'a str> {
        self.string().map_err(msg)
    }
    fn enm(&self) -> Res<&'a str> {
        self.enumeration().map_err(msg)
    }
    fn integer(&self) -> Res<i64> {
        self.int().map_err(msg)
    }
    fn ents(&self) -> Res<Vec<EntityRef<'a>>> {
        self.list().map_err(msg)?.iter().map(|p| p.ent()).collect()
    }
    fn nums(&self) -> Res<Vec<f64>> {
        self.list().map_err(msg)?.iter().map(|p| p.f()).collect()
    }
}

/// Whether `e` is of entity type `name` or of one of its subtypes (listed in [`subtypes`] for
/// the types the mapping asks about), as a simple or a complex instance.
#[must_use]
pub(crate) fn is(e: &EntityRef<'_>, name: &str) -> bool {
    let subs = subtypes(name);
    e.records().any(|r| {
        let n = r.name();
        n == name || subs.contains(&n)
    })
}

/// Subtypes (ISO 10303-42, -43, -46 and the AP schemas) of the supertypes the mapping tests
/// with [`is`]; a simple instance names only its most specific type.
#[must_use]
fn subtypes(name: &str) -> &'static [&'static str] {
    match name {
        "B_SPLINE_SURFACE" => &[
            "B_SPLINE_SURFACE_WITH_KNOTS",
            "UNIFORM_SURFACE",
            "QUASI_UNIFORM_SURFACE",
            "BEZIER_SURFACE",
            "RATIONAL_B_SPLINE_SURFACE",
        ],
        "B_SPLINE_CURVE" => &[
            "B_SPLINE_CURVE_WITH_KNOTS",
            "UNIFORM_CURVE",
            "QUASI_UNIFORM_CURVE",
            "BEZIER_CURVE",
            "RATIONAL_B_SPLINE_CURVE",
        ],
        "SURFACE_CURVE" => &["SEAM_CURVE", "INTERSECTION_CURVE", "BOUNDED_SURFACE_CURVE"],
        "FACE_SURFACE" => &["ADVANCED_FACE"],
        "FACE_BOUND" => &["FACE_OUTER_BOUND"],
        "STYLED_ITEM" => &[
            "OVER_RIDING_STYLED_ITEM",
            "CONTEXT_DEPENDENT_OVER_RIDING_STYLED_ITEM",
            "ANNOTATION_OCCURRENCE",
        ],
        "OVER_RIDING_STYLED_ITEM" => &["CONTEXT_DEPENDENT_OVER_RIDING_STYLED_ITEM"],
        "PRESENTATION_STYLE_ASSIGNMENT" => &["PRESENTATION_STYLE_BY_CONTEXT"],
        "SURFACE_STYLE_RENDERING" => &["SURFACE_STYLE_RENDERING_WITH_PROPERTIES"],
        "PRE_DEFINED_COLOUR" => &["DRAUGHTING_PRE_DEFINED_COLOUR"],
        "SHAPE_REPRESENTATION" => SHAPE_REPRESENTATIONS,
        "REPRESENTATION_RELATIONSHIP" => &[
            "SHAPE_REPRESENTATION_RELATIONSHIP",
            "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION",
            "CONSTRUCTIVE_GEOMETRY_REPRESENTATION_RELATIONSHIP",
        ],
        "PRODUCT_DEFINITION" => &[
            "PRODUCT_DEFINITION_WITH_ASSOCIATED_DOCUMENTS",
            "COMPOSITE_ASSEMBLY_DEFINITION",
        ],
        "PRODUCT_DEFINITION_FORMATION" => &["PRODUCT_DEFINITION_FORMATION_WITH_SPECIFIED_SOURCE"],
        "CARTESIAN_TRANSFORMATION_OPERATOR" => &[
            "CARTESIAN_TRANSFORMATION_OPERATOR_3D",
            "CARTESIAN_TRANSFORMATION_OPERATOR_2D",
        ],
        "CONNECTED_FACE_SET" => &["CLOSED_SHELL", "OPEN_SHELL"],
        _ => &[],
    }
}

/// Shape representations of the AP schemas.
const SHAPE_REPRESENTATIONS: &[&str] = &[
    "ADVANCED_BREP_SHAPE_REPRESENTATION",
    "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
    "FACETED_BREP_SHAPE_REPRESENTATION",
    "GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION",
    "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION",
    "EDGE_BASED_WIREFRAME_SHAPE_REPRESENTATION",
    "SHELL_BASED_WIREFRAME_SHAPE_REPRESENTATION",
    "CSG_SHAPE_REPRESENTATION",
    "TESSELLATED_SHAPE_REPRESENTATION",
];

/// CARTESIAN_POINT (ISO 10303-42 §4.4.4): 1 to 3 coordinates, missing ones 0.
pub(crate) fn point3(e: EntityRef<'_>) -> Res<DVec3> {
    let c = coordinates(e, "CARTESIAN_POINT", "coordinates")?;
    Ok(DVec3::new(
        c.first().copied().unwrap_or(0.0),
        c.get(1).copied().unwrap_or(0.0),
        c.get(2).copied().unwrap_or(0.0),
    ))
}

/// A 2D CARTESIAN_POINT (a point in a parameter space).
pub(crate) fn point2(e: EntityRef<'_>) -> Res<DVec2> {
    let p = point3(e)?;
    Ok(DVec2::new(p.x, p.y))
}

/// The 1–3 finite reals of a point or direction.
fn coordinates(e: EntityRef<'_>, record: &str, name: &'static str) -> Res<Vec<f64>> {
    let p = part(e, record, 1)?.p(0, name)?;
    let c = p.nums()?;
    if c.is_empty() || c.len() > 3 {
        return Err(msg(p.invalid("should have 1 to 3 coordinates")));
    }
    Ok(c)
}

/// DIRECTION (§4.4.10): not normalised here; zero length is an error.
pub(crate) fn direction(e: EntityRef<'_>) -> Res<DVec3> {
    let c = coordinates(e, "DIRECTION", "direction_ratios")?;
    let d = DVec3::new(
        c.first().copied().unwrap_or(0.0),
        c.get(1).copied().unwrap_or(0.0),
        c.get(2).copied().unwrap_or(0.0),
    );
    if d.length_squared() > 0.0 && d.is_finite() {
        Ok(d)
    } else {
        Err(bad(&e, "direction has zero length"))
    }
}

/// VECTOR (§4.4.11): the unit orientation times the magnitude (a length in the context's
/// unit), as LINE's parametrisation `P + t·V` uses it.
pub(crate) fn vector(e: EntityRef<'_>) -> Res<DVec3> {
    let own = part(e, "VECTOR", 1)?;
    let d = direction(own.p(0, "orientation")?.ent()?)?;
    let m = own.p(1, "magnitude")?.f()?;
    if m == 0.0 {
        return Err(bad(&e, "vector has zero magnitude"));
    }
    Ok(d.normalize() * m)
}

/// AXIS2_PLACEMENT_3D (§4.4.17) as the right-handed frame its `build_axes` function defines.
pub(crate) fn frame(e: EntityRef<'_>) -> Res<Frame> {
    if !is(&e, "AXIS2_PLACEMENT_3D") {
        return Err(bad(&e, "should be an AXIS2_PLACEMENT_3D"));
    }
    let own = part(e, "AXIS2_PLACEMENT_3D", 1)?;
    let origin = point3(own.p(0, "location")?.ent()?)?;
    let dir = |i, name| -> Res<Option<DVec3>> {
        match own.p(i, name)?.optional() {
            Some(p) => Ok(Some(direction(p.ent()?)?)),
            None => Ok(None),
        }
    };
    let axis = dir(1, "axis")?;
    let refd = dir(2, "ref_direction")?;
    Frame::from_axis2_placement(origin, axis, refd).map_err(|x| bad(&e, x.to_string()))
}

/// AXIS2_PLACEMENT_2D (§4.4.16): origin and the right-handed axes `x`, `y = x` turned 90°.
pub(crate) fn frame2(e: EntityRef<'_>) -> Res<(DVec2, DVec2, DVec2)> {
    let own = part(e, "AXIS2_PLACEMENT_2D", 1)?;
    let c = point2(own.p(0, "location")?.ent()?)?;
    let x = match own.p(1, "ref_direction")?.optional() {
        Some(p) => direction(p.ent()?)?,
        None => DVec3::X,
    };
    let x = DVec2::new(x.x, x.y);
    if x.length_squared() == 0.0 {
        return Err(bad(&e, "ref_direction is perpendicular to the plane"));
    }
    let x = x.normalize();
    Ok((c, x, x.perp()))
}

/// AXIS1_PLACEMENT (§4.4.15): a point and a unit axis (default +Z).
pub(crate) fn axis1(e: EntityRef<'_>) -> Res<(DVec3, DVec3)> {
    let own = part(e, "AXIS1_PLACEMENT", 1)?;
    let p = point3(own.p(0, "location")?.ent()?)?;
    let d = match own.p(1, "axis")?.optional() {
        Some(a) => direction(a.ent()?)?.normalize(),
        None => DVec3::Z,
    };
    Ok((p, d))
}

/// Element `d` of a pair (`d` is 0 or 1; anything else reads as 1), without an index that could
/// panic.
#[must_use]
pub(crate) fn at<T>(a: &[T; 2], d: usize) -> &T {
    let [x, y] = a;
    if d == 0 { x } else { y }
}

/// Mutable element `d` of a pair (see [`at`]).
#[must_use]
pub(crate) fn at_mut<T>(a: &mut [T; 2], d: usize) -> &mut T {
    let [x, y] = a;
    if d == 0 { x } else { y }
}
