//! How a polynomial-basis object is written.

/// How a polynomial-basis object is written: as a Bézier object (one span on [0, 1]) or as a
/// B-spline. Both are evaluated as B-splines; knot insertion turns a Bézier object into a
/// B-spline object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplineForm {
    Bezier,
    BSpline,
}
