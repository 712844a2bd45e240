//! Seeded random scenes and edit sequences covering every object type of the scene contract.
//!
//! Scenes: degrees 0..=5 (sometimes up to 10), clamped and unclamped knot vectors with repeated
//! interior knots (multiplicity up to the degree, sometimes degree + 1 = a discontinuity), "nice"
//! knots that sample parameters hit exactly, rational weights in [0.2, 5], ERBS curves and
//! surfaces with local Bézier curves/patches of random degree and every B-function (or none,
//! i.e. the default), 2..=40 samples per direction, coordinates of mixed magnitude.

use super::bfunction::BFunction;
use super::eval::{Basis, Point3};
use super::rng::Rng;
use super::scene::{Edit, Elevation, Index, Object, Scene, Shape};

/// The six object types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    BezierCurve,
    BSplineCurve,
    ErbsCurve,
    BezierSurface,
    BSplineSurface,
    ErbsSurface,
}

impl Kind {
    pub const ALL: [Kind; 6] = [
        Kind::BezierCurve,
        Kind::BSplineCurve,
        Kind::ErbsCurve,
        Kind::BezierSurface,
        Kind::BSplineSurface,
        Kind::ErbsSurface,
    ];
    pub const CURVES: [Kind; 3] = [Kind::BezierCurve, Kind::BSplineCurve, Kind::ErbsCurve];
    pub const SURFACES: [Kind; 3] = [Kind::BezierSurface, Kind::BSplineSurface, Kind::ErbsSurface];
}

/// Knobs for the generator.
#[derive(Clone, Debug)]
pub struct Options {
    /// Samples per direction are drawn from 2..=max_samples.
    pub max_samples: usize,
    /// Probability of a degree above 5 (up to 10; 7 for surfaces).
    pub high_degree_chance: f64,
    /// Probability that a Bézier/B-spline object is rational.
    pub rational_chance: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_samples: 40,
            high_degree_chance: 0.12,
            rational_chance: 0.4,
        }
    }
}

/// Per-object coordinate generator: a centre plus per-axis magnitudes spread over 10^±3.
struct Coordinates {
    centre: Point3,
    axis: Point3,
}

impl Coordinates {
    fn new(rng: &mut Rng) -> Coordinates {
        let base = rng.log_range(-3.0, 3.0);
        let axis = std::array::from_fn(|_| base * rng.log_range(-1.0, 1.0));
        let centre = std::array::from_fn(|k| {
            if rng.chance(0.5) {
                0.0
            } else {
                axis[k] * rng.range(-5.0, 5.0)
            }
        });
        Coordinates { centre, axis }
    }

    fn point(&self, rng: &mut Rng) -> Point3 {
        // Occasionally a point far smaller than its neighbours.
        let shrink = if rng.chance(0.1) {
            rng.log_range(-3.0, 0.0)
        } else {
            1.0
        };
        std::array::from_fn(|k| self.centre[k] + shrink * self.axis[k] * rng.range(-1.0, 1.0))
    }
}

fn random_degree(rng: &mut Rng, opts: &Options, high: usize) -> usize {
    if rng.chance(opts.high_degree_chance) {
        rng.int(6, high)
    } else {
        rng.int(0, 5)
    }
}

fn random_samples(rng: &mut Rng, opts: &Options) -> usize {
    // Favour a few special counts: 2, and counts whose (m−1) divides knot spacings nicely.
    if rng.chance(0.2) {
        *rng.pick(&[2, 3, 5, 9, 17, 33])
    } else {
        rng.int(2, opts.max_samples.max(2))
    }
}

fn random_weight(rng: &mut Rng) -> f64 {
    if rng.chance(0.1) {
        *rng.pick(&[0.2, 1.0, 5.0, std::f64::consts::FRAC_1_SQRT_2])
    } else {
        // log-uniform on [0.2, 5]
        (rng.range(0.2f64.ln(), 5f64.ln())).exp()
    }
}

/// A knot "grid": origin and spacing, either exactly representable ("nice", so that sample
/// parameters often coincide with knots) or arbitrary.
fn knot_step(rng: &mut Rng, nice: bool, spacing: f64) -> f64 {
    if nice {
        spacing * *rng.pick(&[0.5, 1.0, 1.0, 2.0])
    } else {
        spacing * rng.range(0.3, 1.0)
    }
}

fn knot_frame(rng: &mut Rng) -> (bool, f64, f64) {
    let nice = rng.chance(0.45);
    if nice {
        let origin = rng.int(0, 8) as f64 - 4.0;
        let spacing = 2f64.powi(rng.int(0, 4) as i32 - 2);
        (true, origin, spacing)
    } else {
        (false, rng.range(-5.0, 5.0), rng.log_range(-1.0, 1.0))
    }
}

/// A valid knot vector for a degree-p B-spline with n control points: n + p + 1 non-decreasing
/// knots, t_p < t_n, every multiplicity ≤ p + 1; clamped or not; interior multiplicities up to p,
/// sometimes p + 1 (a discontinuity inside the domain).
pub fn random_bspline_knots(rng: &mut Rng, p: usize, n: usize) -> Vec<f64> {
    let m = n + p + 1;
    loop {
        let (nice, origin, spacing) = knot_frame(rng);
        let clamp_start = rng.chance(0.5);
        let clamp_end = if rng.chance(0.8) {
            clamp_start
        } else {
            !clamp_start
        };
        // One in five knot vectors may break the curve (interior multiplicity p + 1); those
        // repeat knots eagerly so that full multiplicity actually occurs.
        let discontinuous = rng.chance(0.2);
        let repeat_chance = if discontinuous {
            0.75
        } else {
            *rng.pick(&[0.0, 0.2, 0.4])
        };
        let interior_cap = if discontinuous { p + 1 } else { p.max(1) };
        let mut knots = vec![origin];
        let mut mult = 1;
        for idx in 1..m {
            let last = knots[idx - 1];
            let repeat = if (clamp_start && idx <= p) || (clamp_end && idx > n) {
                true
            } else if clamp_end && idx == n {
                false
            } else {
                let cap = if idx > p && idx < n {
                    interior_cap
                } else {
                    p.max(1)
                };
                mult < cap && rng.chance(repeat_chance)
            };
            if repeat {
                knots.push(last);
                mult += 1;
            } else {
                knots.push(last + knot_step(rng, nice, spacing));
                mult = 1;
            }
        }
        let valid = knots[p] < knots[n] && {
            // every multiplicity ≤ p + 1
            let mut ok = true;
            let mut run = 1;
            for w in knots.windows(2) {
                run = if w[0] == w[1] { run + 1 } else { 1 };
                ok &= run <= p + 1;
            }
            ok
        };
        if valid {
            return knots;
        }
    }
}

/// ERBS knots for n local curves: t_0 = t_1 < t_2 < … < t_n = t_{n+1}.
pub fn random_erbs_knots(rng: &mut Rng, n: usize) -> Vec<f64> {
    let (nice, origin, spacing) = knot_frame(rng);
    let mut knots = vec![origin, origin];
    for _ in 2..=n {
        let last = *knots.last().unwrap();
        knots.push(last + knot_step(rng, nice, spacing));
    }
    knots.push(knots[n]);
    knots
}

fn random_bfunction(rng: &mut Rng) -> Option<BFunction> {
    if rng.chance(1.0 / 6.0) {
        None
    } else {
        Some(*rng.pick(&BFunction::ALL))
    }
}

fn random_points(rng: &mut Rng, coords: &Coordinates, n: usize) -> Vec<Point3> {
    (0..n).map(|_| coords.point(rng)).collect()
}

fn random_grid(rng: &mut Rng, coords: &Coordinates, nu: usize, nv: usize) -> Vec<Vec<Point3>> {
    (0..nu).map(|_| random_points(rng, coords, nv)).collect()
}

/// A random object of the given kind.
pub fn random_object(rng: &mut Rng, kind: Kind, name: &str, opts: &Options) -> Object {
    let coords = Coordinates::new(rng);
    let rational = rng.chance(opts.rational_chance);
    let (shape, samples) = match kind {
        Kind::BezierCurve | Kind::BSplineCurve => {
            let degree = random_degree(rng, opts, 10);
            let (basis, n) = if kind == Kind::BezierCurve {
                (Basis::Bezier, degree + 1)
            } else {
                let n = degree + 1 + rng.int(0, 8);
                let knots = random_bspline_knots(rng, degree, n);
                (Basis::BSpline { degree, knots }, n)
            };
            let points = random_points(rng, &coords, n);
            let weights = rational.then(|| (0..n).map(|_| random_weight(rng)).collect());
            (
                Shape::Curve {
                    basis,
                    points,
                    weights,
                },
                vec![random_samples(rng, opts)],
            )
        }
        Kind::BezierSurface | Kind::BSplineSurface => {
            let degrees = [random_degree(rng, opts, 7), random_degree(rng, opts, 7)];
            let mut counts = [0; 2];
            let mut bases = Vec::new();
            for dir in 0..2 {
                if kind == Kind::BezierSurface {
                    counts[dir] = degrees[dir] + 1;
                    bases.push(Basis::Bezier);
                } else {
                    counts[dir] = degrees[dir] + 1 + rng.int(0, 5);
                    let knots = random_bspline_knots(rng, degrees[dir], counts[dir]);
                    bases.push(Basis::BSpline {
                        degree: degrees[dir],
                        knots,
                    });
                }
            }
            let points = random_grid(rng, &coords, counts[0], counts[1]);
            let weights = rational.then(|| {
                (0..counts[0])
                    .map(|_| (0..counts[1]).map(|_| random_weight(rng)).collect())
                    .collect()
            });
            let basis_v = bases.pop().unwrap();
            let basis_u = bases.pop().unwrap();
            (
                Shape::Surface {
                    basis: [basis_u, basis_v],
                    points,
                    weights,
                },
                vec![random_samples(rng, opts), random_samples(rng, opts)],
            )
        }
        Kind::ErbsCurve => {
            let n = rng.int(2, 6);
            let knots = random_erbs_knots(rng, n);
            let locals = (0..n)
                .map(|_| {
                    let degree = random_degree(rng, opts, 8);
                    random_points(rng, &coords, degree + 1)
                })
                .collect();
            (
                Shape::ErbsCurve {
                    knots,
                    locals,
                    bfunction: random_bfunction(rng),
                },
                vec![random_samples(rng, opts)],
            )
        }
        Kind::ErbsSurface => {
            let (nu, nv) = (rng.int(2, 4), rng.int(2, 4));
            let knots = [random_erbs_knots(rng, nu), random_erbs_knots(rng, nv)];
            let locals = (0..nu)
                .map(|_| {
                    (0..nv)
                        .map(|_| {
                            let (a, b) = (rng.int(0, 4), rng.int(0, 4));
                            random_grid(rng, &coords, a + 1, b + 1)
                        })
                        .collect()
                })
                .collect();
            (
                Shape::ErbsSurface {
                    knots,
                    locals,
                    bfunction: random_bfunction(rng),
                },
                vec![random_samples(rng, opts), random_samples(rng, opts)],
            )
        }
    };
    Object {
        name: name.to_string(),
        shape,
        samples,
    }
}

/// A scene with one random object per entry of `kinds`, named `o0`, `o1`, …
pub fn random_scene(seed: u64, kinds: &[Kind], opts: &Options) -> Scene {
    let mut rng = Rng::new(seed);
    Scene {
        objects: kinds
            .iter()
            .enumerate()
            .map(|(i, &k)| random_object(&mut rng, k, &format!("o{i}"), opts))
            .collect(),
    }
}

fn random_delta(rng: &mut Rng, magnitude: f64) -> Point3 {
    let size = magnitude.max(1e-3) * rng.log_range(-3.0, 0.0);
    std::array::from_fn(|_| size * rng.range(-1.0, 1.0))
}

/// A random affine map, row-major with last row (0, 0, 0, 1): rotation × uniform scale (or, now
/// and then, a general near-identity linear part) plus a translation.
pub fn random_affine(rng: &mut Rng, magnitude: f64) -> [[f64; 4]; 4] {
    let mut m = [[0.0; 4]; 4];
    m[3][3] = 1.0;
    let linear: [[f64; 3]; 3] = match rng.int(0, 3) {
        0 => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        1 => std::array::from_fn(|r| {
            std::array::from_fn(|c| (if r == c { 1.0 } else { 0.0 }) + rng.range(-0.3, 0.3))
        }),
        _ => {
            // Unit quaternion → rotation matrix, times a uniform scale.
            let mut q: [f64; 4] = std::array::from_fn(|_| rng.range(-1.0, 1.0));
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-3);
            q.iter_mut().for_each(|x| *x /= norm);
            let [w, x, y, z] = q;
            let s = rng.range(0.7, 1.4);
            [
                [
                    s * (1.0 - 2.0 * (y * y + z * z)),
                    s * 2.0 * (x * y - w * z),
                    s * 2.0 * (x * z + w * y),
                ],
                [
                    s * 2.0 * (x * y + w * z),
                    s * (1.0 - 2.0 * (x * x + z * z)),
                    s * 2.0 * (y * z - w * x),
                ],
                [
                    s * 2.0 * (x * z - w * y),
                    s * 2.0 * (y * z + w * x),
                    s * (1.0 - 2.0 * (x * x + y * y)),
                ],
            ]
        }
    };
    let translation = random_delta(rng, magnitude);
    for r in 0..3 {
        m[r][..3].copy_from_slice(&linear[r]);
        m[r][3] = translation[r];
    }
    m
}

/// A random edit valid for `object`.
pub fn random_edit(rng: &mut Rng, object: &Object) -> Edit {
    let name = object.name.clone();
    let magnitude = object.magnitude();
    match &object.shape {
        Shape::Curve { points, .. } => {
            let point = Index::One(rng.int(0, points.len() - 1));
            if rng.chance(0.3) {
                Edit::Weight {
                    object: name,
                    point,
                    weight: random_weight(rng),
                }
            } else {
                Edit::PointDelta {
                    object: name,
                    point,
                    delta: random_delta(rng, magnitude),
                }
            }
        }
        Shape::Surface { points, .. } => {
            let point = Index::Two(
                rng.int(0, points.len() - 1),
                rng.int(0, points[0].len() - 1),
            );
            if rng.chance(0.3) {
                Edit::Weight {
                    object: name,
                    point,
                    weight: random_weight(rng),
                }
            } else {
                Edit::PointDelta {
                    object: name,
                    point,
                    delta: random_delta(rng, magnitude),
                }
            }
        }
        Shape::ErbsCurve { locals, .. } => {
            let l = rng.int(0, locals.len() - 1);
            if rng.chance(0.5) {
                Edit::LocalTransform {
                    object: name,
                    local: Index::One(l),
                    matrix: random_affine(rng, magnitude),
                }
            } else {
                Edit::LocalPointDelta {
                    object: name,
                    local: Index::One(l),
                    point: Index::One(rng.int(0, locals[l].len() - 1)),
                    delta: random_delta(rng, magnitude),
                }
            }
        }
        Shape::ErbsSurface { locals, .. } => {
            let (k, l) = (
                rng.int(0, locals.len() - 1),
                rng.int(0, locals[0].len() - 1),
            );
            if rng.chance(0.5) {
                Edit::LocalTransform {
                    object: name,
                    local: Index::Two(k, l),
                    matrix: random_affine(rng, magnitude),
                }
            } else {
                let grid = &locals[k][l];
                Edit::LocalPointDelta {
                    object: name,
                    local: Index::Two(k, l),
                    point: Index::Two(rng.int(0, grid.len() - 1), rng.int(0, grid[0].len() - 1)),
                    delta: random_delta(rng, magnitude),
                }
            }
        }
    }
}

/// `count` random edits on random objects of `scene` (indices stay valid: these edits never
/// change point counts).
pub fn random_edits(rng: &mut Rng, scene: &Scene, count: usize) -> Vec<Edit> {
    (0..count)
        .map(|_| {
            let object = rng.pick(&scene.objects);
            random_edit(rng, object)
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Structural edits (knot insertion, degree elevation)
// ---------------------------------------------------------------------------------------------

/// Knobs for edit lists with structural edits mixed in.
#[derive(Clone, Debug)]
pub struct StructuralMix {
    /// Probability that an edit on a Bézier/B-spline object is structural.
    pub chance: f64,
    /// Elevation never raises a degree above this.
    pub max_degree: usize,
    /// No structural edit on a direction that already has this many control points.
    pub max_points: usize,
}

impl Default for StructuralMix {
    fn default() -> Self {
        StructuralMix {
            chance: 0.3,
            max_degree: 6,
            max_points: 24,
        }
    }
}

/// One direction of a Bézier/B-spline object as (degree, knots, control-point count); a Bézier
/// direction as the clamped B-spline on [0, 1].
fn direction_knots(basis: &Basis, n: usize) -> (usize, Vec<f64>) {
    match basis {
        Basis::Bezier => {
            let mut knots = vec![0.0; n];
            knots.extend(std::iter::repeat_n(1.0, n));
            (n - 1, knots)
        }
        Basis::BSpline { degree, knots } => (*degree, knots.clone()),
    }
}

/// Per direction (degree, knots, point count) of a Bézier/B-spline object; None for ERBS.
pub fn refinable_directions(object: &Object) -> Option<Vec<(usize, Vec<f64>, usize)>> {
    match &object.shape {
        Shape::Curve { basis, points, .. } => {
            let (p, k) = direction_knots(basis, points.len());
            Some(vec![(p, k, points.len())])
        }
        Shape::Surface { basis, points, .. } => {
            let counts = [points.len(), points[0].len()];
            Some(
                (0..2)
                    .map(|d| {
                        let (p, k) = direction_knots(&basis[d], counts[d]);
                        (p, k, counts[d])
                    })
                    .collect(),
            )
        }
        Shape::ErbsCurve { .. } | Shape::ErbsSurface { .. } => None,
    }
}

fn multiplicity(knots: &[f64], t: f64) -> usize {
    knots.iter().filter(|&&k| k == t).count()
}

/// A knot parameter strictly inside the domain with room for at least one more copy, and how
/// many copies to insert: an existing interior knot, a sample parameter, or any value inside a
/// span (short new spans included: `oracle::condition` measures what they cost).
fn random_insertion(
    rng: &mut Rng,
    degree: usize,
    knots: &[f64],
    n: usize,
    params: &[f64],
) -> Option<(f64, usize)> {
    let (a, b) = (knots[degree], knots[n]);
    let room = |t: f64| degree.saturating_sub(multiplicity(knots, t));
    let inside = |t: &f64| a < *t && *t < b && room(*t) > 0;
    let spans: Vec<(f64, f64)> = (degree..n)
        .map(|s| (knots[s], knots[s + 1]))
        .filter(|(lo, hi)| lo < hi)
        .collect();
    let existing: Vec<f64> = knots.iter().copied().filter(inside).collect();
    let on_samples: Vec<f64> = params.iter().copied().filter(inside).collect();
    let t = match rng.int(0, 9) {
        0..=2 if !existing.is_empty() => *rng.pick(&existing),
        3..=4 if !on_samples.is_empty() => *rng.pick(&on_samples),
        _ => {
            let (lo, hi) = *rng.pick(&spans);
            lo + (hi - lo) * rng.range(0.02, 0.98)
        }
    };
    if !inside(&t) {
        return None;
    }
    let times = if rng.chance(0.7) {
        1
    } else {
        rng.int(1, room(t))
    };
    Some((t, times))
}

/// A random `insert_knot` edit valid for `object` (a random direction for surfaces), or None
/// when no direction has room (degree 0, or every candidate knot already at full multiplicity).
pub fn random_insertion_edit(rng: &mut Rng, object: &Object) -> Option<Edit> {
    let directions = refinable_directions(object)?;
    let params = object.params();
    let dir = rng.int(0, directions.len() - 1);
    let (degree, knots, n) = &directions[dir];
    let (t, times) = random_insertion(rng, *degree, knots, *n, &params[dir])?;
    Some(Edit::InsertKnot {
        object: object.name.clone(),
        direction: (directions.len() == 2).then_some(dir),
        t,
        // `times` is optional in the contract when it is 1; write it now and then anyway.
        times: if times == 1 && rng.chance(0.6) {
            None
        } else {
            Some(times)
        },
    })
}

/// A random `elevate_degree` edit valid for `object` that keeps every degree ≤ `mix.max_degree`.
pub fn random_elevation_edit(rng: &mut Rng, object: &Object, mix: &StructuralMix) -> Option<Edit> {
    let directions = refinable_directions(object)?;
    let amount = |degree: usize, rng: &mut Rng| -> usize {
        let e = if rng.chance(0.75) { 1 } else { 2 };
        if degree + e <= mix.max_degree { e } else { 0 }
    };
    let by = if directions.len() == 1 {
        let e = amount(directions[0].0, rng);
        (e > 0).then_some(Elevation::Curve(e))?
    } else {
        let which = rng.int(0, 2); // u only, v only, both
        let u = if which != 1 {
            amount(directions[0].0, rng)
        } else {
            0
        };
        let v = if which != 0 {
            amount(directions[1].0, rng)
        } else {
            0
        };
        if u == 0 && v == 0 {
            return None;
        }
        // A zero direction is written as 0 or left out.
        let write = |e: usize, rng: &mut Rng| (e > 0 || rng.chance(0.5)).then_some(e);
        Elevation::Surface {
            u: write(u, rng),
            v: write(v, rng),
        }
    };
    Some(Edit::ElevateDegree {
        object: object.name.clone(),
        by,
    })
}

/// A random structural edit for `object` (insertion or elevation), or None when none fits
/// `mix` (an ERBS object, a direction at `max_points`, degrees at the limit).
pub fn random_structural_edit(rng: &mut Rng, object: &Object, mix: &StructuralMix) -> Option<Edit> {
    let directions = refinable_directions(object)?;
    if directions.iter().any(|(_, _, n)| *n >= mix.max_points) {
        return None;
    }
    if rng.chance(0.55) {
        random_insertion_edit(rng, object).or_else(|| random_elevation_edit(rng, object, mix))
    } else {
        random_elevation_edit(rng, object, mix).or_else(|| random_insertion_edit(rng, object))
    }
}

/// `count` random edits on random objects of `scene` with structural edits mixed in. Each edit
/// is drawn for the model as edited so far, so later edits address refined control nets.
pub fn random_edits_with_structure(
    rng: &mut Rng,
    scene: &Scene,
    count: usize,
    mix: &StructuralMix,
) -> Vec<Edit> {
    let mut model = scene.clone();
    (0..count)
        .map(|_| {
            let object = &model.objects[rng.int(0, model.objects.len() - 1)];
            let structural = if rng.chance(mix.chance) {
                random_structural_edit(rng, object, mix)
            } else {
                None
            };
            let edit = structural.unwrap_or_else(|| random_edit(rng, object));
            edit.apply(&mut model)
                .unwrap_or_else(|e| panic!("generated an invalid edit {edit:?}: {e}"));
            edit
        })
        .collect()
}
