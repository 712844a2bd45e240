//! The free-form part of an OBJ file as it is written: one [`FreeForm`] per `curv`/`surf`
//! element, with its `cstype`, degrees, parameter ranges, `parm` vectors and control vertices.
//! Nothing here knows the scene model; `map.rs` is the only bridge.

use super::kept::ObjKept;
use glam::DVec3;

/// The polynomial basis named by `cstype` (the supported ones).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// Piecewise Bézier: `parm` holds the segment breakpoints t_0 < … < t_K, and a direction of
    /// degree d has K·d + 1 control vertices (neighbouring segments share one).
    Bezier,
    /// B-spline: `parm` holds the knot vector (control vertices + degree + 1 values).
    BSpline,
}

impl Basis {
    /// The `cstype` word.
    #[must_use]
    pub fn word(self) -> &'static str {
        match self {
            Basis::Bezier => "bezier",
            Basis::BSpline => "bspline",
        }
    }
}

/// One parameter direction of an element: u of a curve, u and v of a surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Direction {
    /// `deg` for this direction.
    pub degree: usize,
    /// The parameter range [start, end] given on the `curv`/`surf` line.
    pub range: [f64; 2],
    /// The `parm` values: knots (B-spline) or segment breakpoints (Bézier).
    pub parm: Vec<f64>,
    /// Control vertices along this direction.
    pub count: usize,
    /// Line of the `parm` statement (for messages).
    pub parm_line: usize,
}

impl Direction {
    /// The knot vector of the equivalent B-spline: the `parm` values themselves, or for a
    /// piecewise Bézier direction the breakpoints with multiplicity d (d + 1 at both ends).
    #[must_use]
    pub fn knots(&self, basis: Basis) -> Vec<f64> {
        match basis {
            Basis::BSpline => self.parm.clone(),
            Basis::Bezier => {
                let d = self.degree;
                let last = self.parm.len() - 1;
                let mut k = Vec::with_capacity(self.count + d + 1);
                for (i, &t) in self.parm.iter().enumerate() {
                    let times = if i == 0 || i == last { d + 1 } else { d };
                    k.extend(std::iter::repeat_n(t, times));
                }
                k
            }
        }
    }

    /// The parameter domain the `parm` vector defines: [t_d, t_n] of the knots, or the first
    /// and last Bézier breakpoint.
    #[must_use]
    pub fn domain(&self, basis: Basis) -> [f64; 2] {
        match basis {
            Basis::BSpline => [self.parm[self.degree], self.parm[self.count]],
            Basis::Bezier => [self.parm[0], self.parm[self.parm.len() - 1]],
        }
    }

    /// Whether the element's range is a proper part of the domain (it is cut on import).
    #[must_use]
    pub fn is_restricted(&self, basis: Basis) -> bool {
        self.range != self.domain(basis)
    }
}

/// One free-form `curv` (one direction) or `surf` (two directions) element.
#[derive(Debug, Clone, PartialEq)]
pub struct FreeForm {
    pub basis: Basis,
    /// `cstype rat …`: the weights are the control vertices' fourth coordinates.
    pub rational: bool,
    /// u, or u and v.
    pub dirs: Vec<Direction>,
    /// Control vertices in file order; for surfaces u varies fastest (`points[j·nu + i]`).
    pub points: Vec<DVec3>,
    /// One weight per control vertex (1 where the `v` statement gave none).
    pub weights: Vec<f64>,
    /// The `o`/`g` name in effect (made unique by the reader: "curve", "surface", ".2", …).
    pub name: Option<String>,
    /// `# prespline samples …` for this element: [m] for curves, [mu, mv] for surfaces.
    pub samples: Option<Vec<usize>>,
    /// `# prespline color r g b`.
    pub color: Option<[f64; 3]>,
    /// Line of the `curv`/`surf` statement.
    pub line: usize,
    /// What the element holds that prespline does not use, written back on save.
    pub carried: ObjKept,
}

impl FreeForm {
    #[must_use]
    pub fn is_surface(&self) -> bool {
        self.dirs.len() == 2
    }

    /// `curv` or `surf`, for messages.
    #[must_use]
    pub fn keyword(&self) -> &'static str {
        if self.is_surface() { "surf" } else { "curv" }
    }
}
