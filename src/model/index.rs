//! How control points and locals are addressed across kinds.

/// A control point or local curve/patch index: one index for curves, two for surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Index2 {
    One(usize),
    Two(usize, usize),
}

/// "3" or "[1, 2]", as messages and the file format write an index.
impl std::fmt::Display for Index2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Index2::One(k) => write!(f, "{k}"),
            Index2::Two(a, b) => write!(f, "[{a}, {b}]"),
        }
    }
}
