//! The one error type of the trim module: one line each, naming the loop, curve and point, so the
//! caller only prefixes the object's name.

use std::fmt;

use glam::DVec2;

/// Why trim input was refused. `Display` is the whole message; loop and curve indices are those
/// of the input (0-based), coordinates are in the surface's parameter space.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrimError {
    #[error("the trimmed surface has no trim loops")]
    NoLoops,
    #[error("trim domain [{}, {}] x [{}, {}] is not a finite, non-empty box", num(&.u.0), num(&.u.1), num(&.v.0), num(&.v.1))]
    BadDomain { u: (f64, f64), v: (f64, f64) },
    #[error("trim tolerance {name} = {} is not a finite number >= 0", num(.value))]
    BadTolerance { name: &'static str, value: f64 },
    #[error("trim loop {loop_index} has no curves")]
    EmptyLoop { loop_index: usize },
    #[error("trim loop {loop_index}: curve {piece} has no points")]
    EmptyCurve { loop_index: usize, piece: usize },
    #[error("trim loop {loop_index} encloses no area")]
    ZeroArea { loop_index: usize },
    #[error("trim loop {loop_index}: curve {piece} has a non-finite point (number {point})")]
    NonFinite {
        loop_index: usize,
        piece: usize,
        point: usize,
    },
    #[error("trim loop {loop_index}: curve {prev} ends at {} and curve {next} starts at {}: a gap of {} (more than {})", pt(.end), pt(.start), num(.gap), num(.tol))]
    Gap {
        loop_index: usize,
        prev: usize,
        next: usize,
        end: DVec2,
        start: DVec2,
        gap: f64,
        tol: f64,
    },
    #[error("trim loop {loop_index} leaves the parameter domain at {} by {} (more than {})", pt(.point), num(.by), num(.tol))]
    OutsideDomain {
        loop_index: usize,
        point: DVec2,
        by: f64,
        tol: f64,
    },
    #[error("trim loop {loop_index} crosses itself near {}", pt(.point))]
    SelfCrossing { loop_index: usize, point: DVec2 },
    #[error("trim loops {first} and {second} cross near {}", pt(.point))]
    LoopsCross {
        first: usize,
        second: usize,
        point: DVec2,
    },
    #[error("trim loops {first} and {second} run along each other near {}", pt(.point))]
    LoopsOverlap {
        first: usize,
        second: usize,
        point: DVec2,
    },
    #[error("hole {loop_index} lies outside every outer loop")]
    HoleOutside { loop_index: usize },
    #[error("hole {loop_index} lies inside hole {parent}, outside every region")]
    HoleInHole { loop_index: usize, parent: usize },
    #[error("outer loop {loop_index} lies inside outer loop {parent} with no hole between them")]
    OuterInOuter { loop_index: usize, parent: usize },
    #[error("trim loop {loop_index}, curve {piece}: {source}")]
    InCurve {
        loop_index: usize,
        piece: usize,
        source: Box<TrimError>,
    },
    #[error("curve range ({}, {}) is not finite or leaves the curve's domain ({}, {})", num(&.range.0), num(&.range.1), num(&.domain.0), num(&.domain.1))]
    BadCurveRange {
        range: (f64, f64),
        domain: (f64, f64),
    },
    #[error("curve is not finite at t = {}", num(.t))]
    CurveNotFinite { t: f64 },
    #[error("flattening needs more than {limit} segments (tolerance {})", num(.tol))]
    TooManySegments { limit: usize, tol: f64 },
    #[error("the trim loops have more than {limit} segments together")]
    TooManyLoopSegments { limit: usize },
    #[error("sample grid: {reason}")]
    BadGrid { reason: String },
}

/// A number printed with at most 4 significant digits and no trailing zeros (`0.06`, `1.414e-6`),
/// so messages stay one short line whatever the rounding noise in the value.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Num(pub f64);

#[must_use]
pub(crate) fn num(x: &f64) -> Num {
    Num(*x)
}

/// A point printed as `(u, v)` with [`Num`] coordinates.
pub(crate) struct Pt(DVec2);

#[must_use]
pub(crate) fn pt(p: &DVec2) -> Pt {
    Pt(*p)
}

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x == 0.0 || !x.is_finite() {
            write!(f, "{x}")
        } else if (1e-3..1e6).contains(&a) {
            let digits = (3 - a.log10().floor() as i32).max(0) as usize;
            let s = format!("{x:.digits$}");
            let s = if s.contains('.') {
                s.trim_end_matches('0').trim_end_matches('.')
            } else {
                &s
            };
            f.write_str(s)
        } else {
            let s = format!("{x:.3e}");
            match s.split_once('e') {
                Some((m, e)) => {
                    let m = if m.contains('.') {
                        m.trim_end_matches('0').trim_end_matches('.')
                    } else {
                        m
                    };
                    write!(f, "{m}e{e}")
                }
                None => f.write_str(&s),
            }
        }
    }
}

impl fmt::Display for Pt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {})", Num(self.0.x), Num(self.0.y))
    }
}
