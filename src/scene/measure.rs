//! What an object covers, measured on its exact geometry (no pre-evaluation): the area of what
//! is drawn — a surface's trimmed part — and the bounding box of it. `prespline info` reports
//! these for every format, and the CAD readers are held to OpenCASCADE's figures with them.
//!
//! The area ∫∫ |S_u × S_v| du dv over the (trimmed) domain is integrated on a uniform grid of
//! cells lined up with the surface's pieces where their breakpoints are evenly spaced:
//! 6 × 6-point Gauss–Legendre on cells inside the trim, and on cells the boundary crosses an
//! exact integral of the Legendre fit of the integrand over the part of the cell inside
//! (`geom::trim::area`). The bounds take the exact points of that grid inside the trim and of
//! the flattened boundary.

use super::SceneObject;
use crate::geom::trim::{
    CELL_NODES, Coverage, Curve2, FLATTEN_TOLERANCE, Integrand, LoopInput, Role, Tolerances, Trim,
    TrimCurve, TrimRegions, flatten_tolerance, flatten_tracked, integrate, regions_at,
};
use crate::model::Model;
use glam::{DVec2, DVec3};

/// Cells per piece between breakpoints (fewer on surfaces of many pieces, down to one), the
/// fewest cells along a direction, and the count of cells per direction beyond which pieces
/// get fewer cells.
const CELLS_PER_PIECE: usize = 4;
const MIN_CELLS: usize = 4;
const MAX_CELLS: usize = 128;
/// The bounds grid's cells per direction, and the finer samples taken around each extreme.
const BOUNDS_CELLS: usize = 32;
const BOUNDS_REFINE: usize = 4;
const REFINE_ROUNDS: usize = 3;
/// The tolerance trims are flattened within for measuring, relative to the domain's diagonal:
/// 25 times the drawing's, a fifth of its segments (the lens correction's error, of the order
/// of the lens times the square of a chord's turning angle, stays below 1e-10 of the area).
const MEASURE_FLATTEN: f64 = 1e-5;
/// Samples along a curve for its bounds.
const CURVE_POINTS: usize = 257;

/// An object's drawn area and bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measure {
    /// Area of what is drawn (0 for curves).
    pub area: f64,
    /// Bounding box of what is drawn; `None` when nothing is (no finite point).
    pub bounds: Option<[DVec3; 2]>,
}

impl SceneObject {
    /// Area and bounds of what is drawn of the object (see the module doc).
    pub fn measure(&self) -> Result<Measure, String> {
        if !self.model.is_surface() {
            return Ok(curve_measure(&self.model));
        }
        let domain = surface_domain(&self.model);
        // The trim flattened coarser than for drawing (the lens correction below makes up
        // for the chords to second order); the drawing's own regions where that fails (loops
        // so close that the coarser polygons would cross).
        let tol = MEASURE_FLATTEN * flatten_tolerance(domain) / FLATTEN_TOLERANCE;
        let (regions, tol) = match &self.trim {
            Some(t) => match regions_at(t.spec(), domain, tol) {
                Ok(r) => (r, tol),
                Err(_) => (t.regions().clone(), flatten_tolerance(domain)),
            },
            None => (rectangle(domain)?, tol),
        };
        let breaks = self.model.kind().breakpoints();
        let tiles_u = tiles(domain[0], breaks.first().map(Vec::as_slice));
        let tiles_v = tiles(domain[1], breaks.get(1).map(Vec::as_slice));
        let speed = Speed(&self.model);
        let mut polygon = 0.0;
        let mut bounds = Extent::default();
        let point = |p: DVec2| speed.partials(p.x, p.y)[0];
        for u in &tiles_u {
            for v in &tiles_v {
                let coverage = Coverage::new(&regions, u, v).map_err(|e| e.to_string())?;
                polygon +=
                    integrate(&regions, u, v, &coverage, speed).map_err(|e| e.to_string())?;
            }
        }
        // A surface of degree 1 in a direction (planes, cylinders, extrusions, rulings) moves
        // each coordinate monotonically along that direction's lines (linearly, or as a ratio
        // of linear functions where rational): its extremes lie on the boundary, sampled below.
        let ruled = self
            .model
            .kind()
            .tensor()
            .is_some_and(|t| t.degree().contains(&1));
        if !ruled {
            surface_bounds(&regions, domain, &point, &mut bounds)?;
        }
        let lenses = match &self.trim {
            Some(t) => lens_correction(t.spec(), &regions, tol, &|a, b| speed.at(a, b))?,
            None => 0.0,
        };
        let area = polygon + lenses;
        // The boundary, each of its segments cut as finely as the bounds grid (a long straight
        // edge in parameter space is a curve on the surface: a line across a cylinder's top).
        let su = (domain[0].1 - domain[0].0) / BOUNDS_CELLS as f64;
        let sv = (domain[1].1 - domain[1].0) / BOUNDS_CELLS as f64;
        for l in regions.loops() {
            let points = l.points();
            if let Some(&first) = points.first() {
                bounds.include(point(first));
            }
            for w in points.windows(2) {
                let (a, b) = (w[0], w[1]);
                let n = ((b.x - a.x).abs() / su).max((b.y - a.y).abs() / sv).ceil();
                let n = if n.is_finite() {
                    (n as usize).clamp(1, 4096)
                } else {
                    1
                };
                // The segment's start is the previous one's end, already included.
                for k in 1..=n {
                    bounds.include(point(a.lerp(b, k as f64 / n as f64)));
                }
            }
        }
        Ok(Measure {
            area,
            bounds: bounds.get(),
        })
    }
}

/// The area integrand |S_u × S_v| of a surface model: through its tensor-product form where it
/// has one (a cell's Gauss nodes evaluated together), else its kind's derivatives.
#[derive(Clone, Copy)]
struct Speed<'a>(&'a Model);

impl Speed<'_> {
    fn partials(&self, u: f64, v: f64) -> [DVec3; 3] {
        let kind = self.0.kind();
        if let Some(t) = kind.tensor() {
            return t.first_partials(u, v);
        }
        let mut d = [DVec3::ZERO; 3];
        kind.derivatives_at([u, v], 1, &[(0, 0), (1, 0), (0, 1)], &mut d);
        d
    }
}

impl Integrand for Speed<'_> {
    fn at(&self, u: f64, v: f64) -> f64 {
        let d = self.partials(u, v);
        d[1].cross(d[2]).length()
    }

    fn grid(
        &self,
        us: &[f64; CELL_NODES],
        vs: &[f64; CELL_NODES],
        out: &mut [[f64; CELL_NODES]; CELL_NODES],
    ) {
        let Some(t) = self.0.kind().tensor() else {
            for (a, &u) in us.iter().enumerate() {
                for (b, &v) in vs.iter().enumerate() {
                    out[a][b] = self.at(u, v);
                }
            }
            return;
        };
        let mut d = [[DVec3::ZERO; 3]; CELL_NODES * CELL_NODES];
        t.first_partials_grid(us, vs, &mut d);
        for (a, row) in out.iter_mut().enumerate() {
            for (b, o) in row.iter_mut().enumerate() {
                let p = &d[a * CELL_NODES + b];
                *o = p[1].cross(p[2]).length();
            }
        }
    }
}

/// What the flattened polygon leaves out of the area: for every chord of every curved trim
/// piece (flattened exactly as the regions were), the lens between the chord and its stretch
/// of curve — ⅔ · chord · sagitta, the parabola through the curve's midpoint, whose error is of
/// the order of the square of the stretch's turning angle (below 1e-5 of the lens for the
/// flattening tolerance, below 1e-12 of the area) — times the integrand at that midpoint;
/// added where the curve bulges out of the polygon and taken away where it bulges in (its
/// midpoint inside), so no orientation needs tracking.
fn lens_correction(
    spec: &Trim,
    regions: &TrimRegions,
    tol: f64,
    f: &dyn Fn(f64, f64) -> f64,
) -> Result<f64, String> {
    let mut sum = 0.0;
    let (mut points, mut params) = (Vec::new(), Vec::new());
    for piece in spec.loops.iter().flat_map(|l| &l.pieces) {
        if piece.curve.is_straight() {
            continue;
        }
        points.clear();
        params.clear();
        flatten_tracked(
            &piece.curve as &dyn Curve2,
            piece.range,
            tol,
            &mut points,
            Some(&mut params),
        )
        .map_err(|e| e.to_string())?;
        for w in params.windows(2) {
            sum += lens(&piece.curve, w[0], w[1], regions, f);
        }
    }
    Ok(sum)
}

/// The signed contribution of the lens between the chord and the curve on [t0, t1].
fn lens(
    c: &TrimCurve,
    t0: f64,
    t1: f64,
    regions: &TrimRegions,
    f: &dyn Fn(f64, f64) -> f64,
) -> f64 {
    let (a, b) = (c.point(t0), c.point(t1));
    let m = c.point(0.5 * (t0 + t1));
    let chord = b - a;
    let length = chord.length();
    if length == 0.0 {
        return 0.0;
    }
    let sagitta = chord.perp_dot(m - a).abs() / length;
    let area = 2.0 / 3.0 * length * sagitta;
    if area == 0.0 {
        return 0.0;
    }
    let sign = if regions.contains(m) { -1.0 } else { 1.0 };
    sign * area * f(m.x, m.y)
}

/// The bounds of the surface points inside the trim: a uniform grid of [`BOUNDS_CELLS`] cells
/// a side, then, around the grid point of each of the six extremes, [`REFINE_ROUNDS`] rounds
/// of samples [`BOUNDS_REFINE`] times finer each, centred on the best so far (a curved face's
/// extreme lies between grid points: an 11° cell of a cylinder misses 0.5 % of its radius, the
/// third round's 0.17° steps 1e-6).
fn surface_bounds(
    regions: &TrimRegions,
    domain: [(f64, f64); 2],
    point: &dyn Fn(DVec2) -> DVec3,
    bounds: &mut Extent,
) -> Result<(), String> {
    let axis = |(lo, hi): (f64, f64)| -> Vec<f64> {
        (0..=BOUNDS_CELLS)
            .map(|k| {
                if k == BOUNDS_CELLS {
                    hi
                } else {
                    lo + (hi - lo) * k as f64 / BOUNDS_CELLS as f64
                }
            })
            .collect()
    };
    let (u, v) = (axis(domain[0]), axis(domain[1]));
    let coverage = Coverage::new(regions, &u, &v).map_err(|e| e.to_string())?;
    // Per axis and side: the extreme value and where on the grid it is.
    let mut extremes = [(f64::INFINITY, DVec2::ZERO); 6];
    for (i, &a) in u.iter().enumerate() {
        for (j, &b) in v.iter().enumerate() {
            if !coverage.sample_inside(i, j) {
                continue;
            }
            let uv = DVec2::new(a, b);
            let p = point(uv);
            bounds.include(p);
            for (k, e) in extremes.iter_mut().enumerate() {
                let x = if k % 2 == 0 { p[k / 2] } else { -p[k / 2] };
                if x < e.0 {
                    *e = (x, uv);
                }
            }
        }
    }
    let (hu, hv) = (u[1] - u[0], v[1] - v[0]);
    for &(x, at) in &extremes {
        if !x.is_finite() {
            continue;
        }
        let k = extremes
            .iter()
            .position(|e| e.1 == at && e.0 == x)
            .unwrap_or(0);
        let value = |p: DVec3| if k % 2 == 0 { p[k / 2] } else { -p[k / 2] };
        // Rounds of (2R + 1)² samples around the best point so far, each R times finer.
        let (mut best, mut best_at) = (x, at);
        let mut step = DVec2::new(hu, hv) / BOUNDS_REFINE as f64;
        for _ in 0..REFINE_ROUNDS {
            let centre = best_at;
            for a in -(BOUNDS_REFINE as i32)..=BOUNDS_REFINE as i32 {
                for b in -(BOUNDS_REFINE as i32)..=BOUNDS_REFINE as i32 {
                    let uv = centre + DVec2::new(f64::from(a) * step.x, f64::from(b) * step.y);
                    let inside = (domain[0].0..=domain[0].1).contains(&uv.x)
                        && (domain[1].0..=domain[1].1).contains(&uv.y)
                        && regions.contains(uv);
                    if inside {
                        let p = point(uv);
                        bounds.include(p);
                        if value(p) < best {
                            (best, best_at) = (value(p), uv);
                        }
                    }
                }
            }
            step /= BOUNDS_REFINE as f64;
        }
    }
    Ok(())
}

/// A growing bounding box.
#[derive(Default)]
struct Extent(Option<[DVec3; 2]>);

impl Extent {
    fn include(&mut self, p: DVec3) {
        if !p.is_finite() {
            return;
        }
        self.0 = Some(match self.0 {
            None => [p, p],
            Some([lo, hi]) => [lo.min(p), hi.max(p)],
        });
    }

    fn get(&self) -> Option<[DVec3; 2]> {
        self.0
    }
}

fn surface_domain(model: &Model) -> [(f64, f64); 2] {
    let d = model.domain();
    [d[0], d.get(1).copied().unwrap_or(d[0])]
}

/// The untrimmed domain as one outer loop.
fn rectangle(d: [(f64, f64); 2]) -> Result<TrimRegions, String> {
    let ((a, b), (c, e)) = (d[0], d[1]);
    let corners = vec![
        DVec2::new(a, c),
        DVec2::new(b, c),
        DVec2::new(b, e),
        DVec2::new(a, e),
        DVec2::new(a, c),
    ];
    let input = LoopInput {
        pieces: vec![corners],
        role: Some(Role::Outer),
    };
    TrimRegions::new(&[input], d, &Tolerances::default()).map_err(|e| e.to_string())
}

/// The integration grid along one direction, as tiles of uniform cells whose edges never
/// straddle a breakpoint (the integrand is smooth only between them): one tile of
/// [`CELLS_PER_PIECE`] cells per piece when the breakpoints are evenly spaced, else one tile
/// per piece. At least [`MIN_CELLS`] cells in all; a tile has at most [`MAX_CELLS`].
fn tiles((a, b): (f64, f64), breaks: Option<&[f64]>) -> Vec<Vec<f64>> {
    let mut breaks = match breaks {
        Some(k) if k.len() >= 2 => k.to_vec(),
        _ => vec![a, b],
    };
    // Pieces shorter than 1e-6 of the domain (CAD files have them) join their neighbour: they
    // hold no area worth a tile, and cells that small fall below the rounding of a grid.
    let tiny = 1e-6 * (b - a);
    breaks.dedup_by(|next, kept| *next - *kept < tiny && *kept != a);
    let n = breaks.len();
    if n > 2 && breaks[n - 1] - breaks[n - 2] < tiny {
        breaks[n - 2] = b;
        breaks.pop();
    }
    let pieces = breaks.len() - 1;
    let len = b - a;
    let expected = len / pieces as f64;
    let even = breaks
        .windows(2)
        .all(|w| ((w[1] - w[0]) - expected).abs() <= 1e-9 * len.abs());
    let uniform = |lo: f64, hi: f64, cells: usize| -> Vec<f64> {
        (0..=cells)
            .map(|k| {
                if k == cells {
                    hi
                } else {
                    lo + (hi - lo) * k as f64 / cells as f64
                }
            })
            .collect()
    };
    // Fewer cells per piece on surfaces with many pieces (CAD fillets have hundreds): a
    // piece is polynomial (rational) of the surface's degree, which 6-point Gauss integrates
    // well on its own, and the count of cells per direction stays near MAX_CELLS.
    let per = (MAX_CELLS / pieces)
        .clamp(1, CELLS_PER_PIECE)
        .max(MIN_CELLS.div_ceil(pieces));
    if even {
        return vec![uniform(a, b, pieces * per)];
    }
    breaks
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| uniform(w[0], w[1], per))
        .collect()
}

/// A curve's bounds from points along it (the curve is what is drawn; it has no area).
fn curve_measure(model: &Model) -> Measure {
    let (a, b) = model.domain()[0];
    let kind = model.kind();
    let mut bounds = Extent::default();
    for k in 0..CURVE_POINTS {
        let t = a + (b - a) * k as f64 / (CURVE_POINTS - 1) as f64;
        let mut d = [DVec3::ZERO];
        kind.derivatives_at([t, 0.0], 0, &[(0, 0)], &mut d);
        bounds.include(d[0]);
    }
    Measure {
        area: 0.0,
        bounds: bounds.get(),
    }
}
