//! ERBS curves and surfaces: the models and their edits. Edits address local curves and patches
//! by a path descending through ERBS locals (hierarchical editing), and refine: a knot inserted
//! into the object or into an ERBS local, a polynomial local turned into an ERBS local of its own.
//! One generic edit type serves both kinds through [`ErbsNet`].

pub mod curve_sampler;
pub mod surface_sampler;

use crate::geom::erbs::{ErbsCurve, ErbsSurface, LocalCurve, LocalPatch, MAX_NESTING};
use crate::geom::shape::{ShapeChange, erbs_knot_probes, erbs_probes, shape_change};
use crate::geom::{BFunctionKind, GeomError};
use crate::model::Kind;
use crate::model::edit::{EditError, KindEdit, Target, check_shape_kept};
use crate::model::points::check_vector;
use crate::model::registry::IntoObject;
use crate::model::{Index2, MAX_CURVE_SAMPLES, MAX_DEGREE, check_samples, check_surface_samples};
use crate::sampling::SampleMode;
use crate::sampling::budget::check_build;
use curve_sampler::ErbsCurveSampler;
use glam::{DMat4, DVec3, DVec4};
use std::fmt::Debug;
use std::hash::Hash;
use surface_sampler::ErbsSurfaceSampler;

/// An ERBS curve with its sample count.
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsCurveModel {
    curve: ErbsCurve,
    samples: usize,
}

impl ErbsCurveModel {
    pub fn new(curve: ErbsCurve, samples: usize) -> Result<Self, EditError> {
        check_samples(samples, MAX_CURVE_SAMPLES)?;
        Ok(Self { curve, samples })
    }

    pub fn curve(&self) -> &ErbsCurve {
        &self.curve
    }

    pub fn samples(&self) -> usize {
        self.samples
    }
}

/// An ERBS surface with its sample counts [mu, mv].
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsSurfaceModel {
    surface: ErbsSurface,
    samples: [usize; 2],
}

impl ErbsSurfaceModel {
    pub fn new(surface: ErbsSurface, samples: [usize; 2]) -> Result<Self, EditError> {
        check_surface_samples(samples)?;
        Ok(Self { surface, samples })
    }

    pub fn surface(&self) -> &ErbsSurface {
        &self.surface
    }

    pub fn samples(&self) -> [usize; 2] {
        self.samples
    }
}

impl Kind for ErbsCurveModel {
    type Edit = ErbsCurveEdit;
    type Sampler = ErbsCurveSampler;
    const SURFACE: bool = false;
    const LABEL: &'static str = "ERBS curve";

    fn type_name(&self) -> &'static str {
        "erbs_curve"
    }

    fn sample_dims(&self) -> [usize; 2] {
        [self.samples, 1]
    }

    fn domain(&self) -> Vec<(f64, f64)> {
        vec![self.curve.domain()]
    }

    fn sampler(&self, mode: SampleMode) -> ErbsCurveSampler {
        ErbsCurveSampler::new(self.clone(), mode.layout().0)
    }
}

impl Kind for ErbsSurfaceModel {
    type Edit = ErbsSurfaceEdit;
    type Sampler = ErbsSurfaceSampler;
    const SURFACE: bool = true;
    const LABEL: &'static str = "ERBS surface";

    fn type_name(&self) -> &'static str {
        "erbs_surface"
    }

    fn sample_dims(&self) -> [usize; 2] {
        self.samples
    }

    fn domain(&self) -> Vec<(f64, f64)> {
        self.surface.domain().to_vec()
    }

    fn sampler(&self, mode: SampleMode) -> ErbsSurfaceSampler {
        let (_, set, normals) = mode.layout();
        ErbsSurfaceSampler::new(self.clone(), set, normals)
    }
}

/// The path to a local curve or patch: one index (curves) or index pair (surfaces) per ERBS
/// level, from the object's own locals down. At most [`MAX_NESTING`] steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct LocalPath<I> {
    len: u8,
    steps: [I; MAX_NESTING],
}

/// "2 → [1, 0]": the steps from the object's own locals down.
impl<I: Copy + std::fmt::Display> std::fmt::Display for LocalPath<I> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (k, step) in self.steps[..usize::from(self.len)].iter().enumerate() {
            if k > 0 {
                f.write_str(" → ")?;
            }
            write!(f, "{step}")?;
        }
        Ok(())
    }
}

impl<I: Copy + Default> LocalPath<I> {
    /// `None` for an empty or too long path.
    pub fn new(steps: &[I]) -> Option<Self> {
        if steps.is_empty() || steps.len() > MAX_NESTING {
            return None;
        }
        let mut s = [I::default(); MAX_NESTING];
        s[..steps.len()].copy_from_slice(steps);
        Some(Self {
            len: steps.len() as u8,
            steps: s,
        })
    }

    /// A top-level local.
    pub fn top(i: I) -> Self {
        Self::new(&[i]).expect("one step")
    }

    pub fn steps(&self) -> &[I] {
        &self.steps[..self.len as usize]
    }

    /// The path one level deeper.
    pub fn child(&self, i: I) -> Option<Self> {
        let mut v = self.steps().to_vec();
        v.push(i);
        Self::new(&v)
    }

    /// Whether this path is `prefix` or lies below it.
    pub fn starts_with(&self, prefix: &LocalPath<I>) -> bool
    where
        I: PartialEq,
    {
        self.steps().starts_with(prefix.steps())
    }

    /// The same path with index pairs for both kinds (what [`Target`] compares).
    pub fn key(&self) -> LocalPath<Index2>
    where
        I: Into<Index2>,
    {
        LocalPath {
            len: self.len,
            steps: self.steps.map(Into::into),
        }
    }
}

impl LocalPath<Index2> {
    /// The curve form of a path of single indices.
    pub fn to_curve(&self) -> Option<LocalPath<usize>> {
        let steps: Option<Vec<usize>> = self
            .steps()
            .iter()
            .map(|i| match *i {
                Index2::One(k) => Some(k),
                Index2::Two(..) => None,
            })
            .collect();
        LocalPath::new(&steps?)
    }

    /// The surface form of a path of index pairs.
    pub fn to_surface(&self) -> Option<LocalPath<[usize; 2]>> {
        let steps: Option<Vec<[usize; 2]>> = self
            .steps()
            .iter()
            .map(|i| match *i {
                Index2::Two(k, l) => Some([k, l]),
                Index2::One(_) => None,
            })
            .collect();
        LocalPath::new(&steps?)
    }
}

impl Default for Index2 {
    fn default() -> Self {
        Index2::One(0)
    }
}

/// What the ERBS edits need of an ERBS curve or surface: locals by path, their control points,
/// refinement and construction. Implemented once per kind, so [`ErbsEdit`] is written once.
pub trait ErbsNet: Clone + PartialEq + Debug + Sized {
    /// A local's index at one level, and a control point's index in a polynomial local.
    type Index: Copy + Default + PartialEq + Eq + Hash + Debug + Into<Index2>;
    type Local: Clone + PartialEq + Debug;
    /// Where a refinement inserts: t (curves), or a direction and t (surfaces).
    type Knot: Copy + PartialEq + Debug;
    /// A degree (curves) or degrees per direction (surfaces).
    type Degree: Copy + PartialEq + Debug;
    /// How many locals a construction makes.
    type Count: Copy + PartialEq + Debug;
    type Model: Clone + PartialEq + Debug;

    fn of(model: &Self::Model) -> &Self;
    fn of_mut(model: &mut Self::Model) -> &mut Self;

    fn local_at(&self, path: &[Self::Index]) -> Option<&Self::Local>;
    /// An error naming the first step of `path` that does not exist.
    fn check_path(&self, path: &[Self::Index]) -> Result<(), EditError>;
    /// The control points of a polynomial local (none for an ERBS local).
    fn points(local: &Self::Local) -> Option<&[DVec3]>;
    fn check_point(local: &Self::Local, p: Self::Index) -> Result<(), EditError>;
    fn as_erbs(local: &Self::Local) -> Option<&Self>;
    fn wrap(e: Self) -> Self::Local;

    fn transform_local(&mut self, path: &[Self::Index], a: &DMat4);
    fn translate_local_point(&mut self, path: &[Self::Index], p: Self::Index, d: DVec3);
    fn set_local_points(&mut self, path: &[Self::Index], points: &[DVec3]);
    fn set_local(&mut self, path: &[Self::Index], local: Self::Local);

    /// Local refinement (see [`ErbsCurve::insert_knot`]).
    fn refine(&self, at: Self::Knot, degree: Option<Self::Degree>) -> Result<Self, GeomError>;
    /// An ERBS local Hermite-interpolating a polynomial local (see [`ErbsCurve::from_curve`]).
    fn build(
        local: &Self::Local,
        count: Self::Count,
        degree: Self::Degree,
        bf: BFunctionKind,
    ) -> Result<Self, GeomError>;
    fn bfunction(&self) -> BFunctionKind;
    fn check_degree(d: Self::Degree) -> Result<(), EditError>;

    /// What the kind is called in messages ("curve", "surface"), and one of its locals.
    const NOUN: &'static str;
    const LOCAL_NOUN: &'static str;
    /// How far `refined` (this net refined at `at`) moved the shape where local refinement
    /// keeps it: at the knots, at `at`, and on the intervals beside the refined one.
    fn refinement_change(&self, refined: &Self, at: Self::Knot) -> ShapeChange;
    /// How far `built` (an ERBS local built from `local`) lies from `local` at its knots, where
    /// it interpolates it.
    fn build_change(local: &Self::Local, built: &Self) -> ShapeChange;
}

/// An edit of one local curve or patch.
#[derive(Debug, Clone, PartialEq)]
pub enum LocalEdit<I> {
    /// Map every control point (at any depth) by p ↦ (A·[p;1]).xyz, A affine.
    Transform { local: LocalPath<I>, matrix: DMat4 },
    /// Translate one control point of a polynomial local.
    MovePoint {
        local: LocalPath<I>,
        point: I,
        delta: DVec3,
    },
    /// Set every control point of a polynomial local exactly (undo).
    SetPoints {
        local: LocalPath<I>,
        points: Vec<DVec3>,
    },
}

impl<I: Copy + Default + PartialEq> LocalEdit<I> {
    pub fn local(&self) -> LocalPath<I> {
        match self {
            LocalEdit::Transform { local, .. }
            | LocalEdit::MovePoint { local, .. }
            | LocalEdit::SetPoints { local, .. } => *local,
        }
    }

    /// Transforms compose (A2·A1), moves of one local point add up, the last set wins.
    #[must_use]
    pub fn merge(&self, next: &Self) -> Option<Self> {
        use LocalEdit::*;
        if self.local() != next.local() {
            return None;
        }
        match (self, next) {
            (Transform { local, matrix: a }, Transform { matrix: b, .. }) => Some(Transform {
                local: *local,
                matrix: *b * *a,
            }),
            (
                MovePoint {
                    local,
                    point,
                    delta: a,
                },
                MovePoint {
                    point: q, delta: b, ..
                },
            ) if point == q => Some(MovePoint {
                local: *local,
                point: *point,
                delta: *a + *b,
            }),
            (_, SetPoints { .. }) => Some(next.clone()),
            _ => None,
        }
    }
}

/// Edits of an ERBS curve or surface.
#[derive(Debug, Clone, PartialEq)]
pub enum ErbsEdit<N: ErbsNet> {
    Local(LocalEdit<N::Index>),
    /// Local refinement of the object (`local: None`) or of the ERBS local at `local`: a knot
    /// between two others becomes the centre of a new Hermite local of `degree` (default: its
    /// neighbours' larger degree).
    InsertKnot {
        local: Option<LocalPath<N::Index>>,
        at: N::Knot,
        degree: Option<N::Degree>,
    },
    /// The polynomial local at `local` becomes an ERBS local of its own, built from it.
    ToErbs {
        local: LocalPath<N::Index>,
        count: N::Count,
        degree: N::Degree,
    },
    /// Put back the local at `local` exactly (undo).
    SetLocal {
        local: LocalPath<N::Index>,
        to: Box<N::Local>,
    },
    /// Put back the whole object exactly (undo of a refinement of the object).
    Restore(Box<N>),
}

pub type ErbsCurveEdit = ErbsEdit<ErbsCurve>;
pub type ErbsSurfaceEdit = ErbsEdit<ErbsSurface>;

/// A finite affine matrix: last row (0, 0, 0, 1).
fn check_affine(m: &DMat4) -> Result<(), EditError> {
    if !m.is_finite() {
        return Err(EditError::new(
            "transform",
            "entries must be finite numbers",
        ));
    }
    if m.row(3) != DVec4::W {
        return Err(EditError::new(
            "transform",
            format!(
                "not affine: the last row must be [0, 0, 0, 1], found {:?}",
                m.row(3).to_array()
            ),
        ));
    }
    Ok(())
}

fn local_of<'a, N: ErbsNet>(
    net: &'a N,
    path: &LocalPath<N::Index>,
) -> Result<&'a N::Local, EditError> {
    net.check_path(path.steps())?;
    net.local_at(path.steps())
        .ok_or_else(|| EditError::new("local", format!("no local at {:?}", path.steps())))
}

/// The error for step `depth` of a path (`what` the index problem).
fn step_error(depth: usize, what: EditError) -> EditError {
    if depth == 0 {
        what
    } else {
        EditError::new(
            "local",
            format!("step {depth} of the path: {}", what.message),
        )
    }
}

fn polynomial_points<N: ErbsNet>(local: &N::Local) -> Result<&[DVec3], EditError> {
    N::points(local).ok_or_else(|| {
        EditError::new(
            "point",
            "an ERBS local has no control points of its own: address one of its locals",
        )
    })
}

fn geom(e: GeomError) -> EditError {
    EditError::new(e.field, e.message)
}

impl<N: ErbsNet> ErbsEdit<N> {
    fn validate_net(&self, net: &N) -> Result<(), EditError> {
        match self {
            ErbsEdit::Local(e) => {
                let local = local_of(net, &e.local())?;
                match e {
                    LocalEdit::Transform { matrix, .. } => check_affine(matrix),
                    LocalEdit::MovePoint { point, delta, .. } => {
                        polynomial_points::<N>(local)?;
                        N::check_point(local, *point)?;
                        check_vector("delta", *delta)
                    }
                    LocalEdit::SetPoints { points, .. } => {
                        let own = polynomial_points::<N>(local)?;
                        if points.len() != own.len() {
                            return Err(EditError::new(
                                "points",
                                format!("{} points for a local with {}", points.len(), own.len()),
                            ));
                        }
                        points.iter().try_for_each(|&p| check_vector("points", p))
                    }
                }
            }
            ErbsEdit::InsertKnot { local, at, degree } => {
                if let Some(d) = degree {
                    N::check_degree(*d)?;
                }
                let target = match local {
                    None => net,
                    Some(path) => N::as_erbs(local_of(net, path)?).ok_or_else(|| {
                        EditError::new(
                            "insert_knot",
                            "the local is not an ERBS curve: only ERBS locals are refined (turn it into one first)",
                        )
                    })?,
                };
                let refined = target.refine(*at, *degree).map_err(geom)?;
                check_shape_kept(
                    "insert_knot",
                    N::NOUN,
                    target.refinement_change(&refined, *at),
                )
            }
            ErbsEdit::ToErbs {
                local,
                count,
                degree,
            } => {
                N::check_degree(*degree)?;
                let l = local_of(net, local)?;
                polynomial_points::<N>(l)
                    .map_err(|_| EditError::new("to_erbs", "the local already is an ERBS local"))?;
                if local.steps().len() >= MAX_NESTING {
                    return Err(EditError::new(
                        "to_erbs",
                        format!("ERBS locals nest at most {MAX_NESTING} levels deep"),
                    ));
                }
                let built = N::build(l, *count, *degree, net.bfunction()).map_err(geom)?;
                check_shape_kept("to_erbs", N::LOCAL_NOUN, N::build_change(l, &built))
            }
            ErbsEdit::SetLocal { local, .. } => local_of(net, local).map(|_| ()),
            ErbsEdit::Restore(_) => Ok(()),
        }
    }

    fn apply_net(&self, net: &mut N) {
        match self {
            ErbsEdit::Local(e) => match e {
                LocalEdit::Transform { local, matrix } => {
                    net.transform_local(local.steps(), matrix)
                }
                LocalEdit::MovePoint {
                    local,
                    point,
                    delta,
                } => net.translate_local_point(local.steps(), *point, *delta),
                LocalEdit::SetPoints { local, points } => {
                    net.set_local_points(local.steps(), points)
                }
            },
            ErbsEdit::InsertKnot { local, at, degree } => match local {
                None => {
                    if let Ok(r) = net.refine(*at, *degree) {
                        *net = r;
                    }
                }
                Some(path) => {
                    let refined = net
                        .local_at(path.steps())
                        .and_then(N::as_erbs)
                        .and_then(|e| e.refine(*at, *degree).ok());
                    if let Some(r) = refined {
                        net.set_local(path.steps(), N::wrap(r));
                    }
                }
            },
            ErbsEdit::ToErbs {
                local,
                count,
                degree,
            } => {
                let bf = net.bfunction();
                let built = net
                    .local_at(local.steps())
                    .and_then(|l| N::build(l, *count, *degree, bf).ok());
                if let Some(e) = built {
                    net.set_local(local.steps(), N::wrap(e));
                }
            }
            ErbsEdit::SetLocal { local, to } => net.set_local(local.steps(), (**to).clone()),
            ErbsEdit::Restore(to) => *net = (**to).clone(),
        }
    }

    fn inverse_net(&self, net: &N) -> Self {
        let set_local = |path: LocalPath<N::Index>| match net.local_at(path.steps()) {
            Some(l) => ErbsEdit::SetLocal {
                local: path,
                to: Box::new(l.clone()),
            },
            None => ErbsEdit::Restore(Box::new(net.clone())),
        };
        match self {
            ErbsEdit::Local(e) => {
                let path = e.local();
                match net.local_at(path.steps()).and_then(N::points) {
                    Some(points) => ErbsEdit::Local(LocalEdit::SetPoints {
                        local: path,
                        points: points.to_vec(),
                    }),
                    None => set_local(path),
                }
            }
            ErbsEdit::InsertKnot { local: Some(p), .. }
            | ErbsEdit::ToErbs { local: p, .. }
            | ErbsEdit::SetLocal { local: p, .. } => set_local(*p),
            ErbsEdit::InsertKnot { local: None, .. } | ErbsEdit::Restore(_) => {
                ErbsEdit::Restore(Box::new(net.clone()))
            }
        }
    }
}

impl<N: ErbsNet> KindEdit for ErbsEdit<N>
where
    ErbsEdit<N>: IntoObject,
{
    type Model = N::Model;

    fn validate(&self, m: &N::Model) -> Result<(), EditError> {
        self.validate_net(N::of(m))
    }

    fn apply(&self, m: &mut N::Model) {
        self.apply_net(N::of_mut(m));
    }

    fn inverse(&self, m: &N::Model) -> Self {
        self.inverse_net(N::of(m))
    }

    fn target(&self) -> Target {
        match self {
            ErbsEdit::Local(e) => Target::Local(e.local().key()),
            _ => Target::Structure,
        }
    }

    fn merge(&self, next: &Self) -> Option<Self> {
        match (self, next) {
            (ErbsEdit::Local(a), ErbsEdit::Local(b)) => a.merge(b).map(ErbsEdit::Local),
            _ => None,
        }
    }
}

fn check_count(field: &'static str, i: usize, n: usize) -> Result<(), EditError> {
    if i < n {
        Ok(())
    } else {
        Err(EditError::new(
            field,
            format!(
                "index {i} out of range (valid: 0..={})",
                n.saturating_sub(1)
            ),
        ))
    }
}

fn check_pair(
    field: &'static str,
    [i, j]: [usize; 2],
    [n, m]: [usize; 2],
) -> Result<(), EditError> {
    if i < n && j < m {
        return Ok(());
    }
    Err(EditError::new(
        field,
        format!(
            "index [{i}, {j}] out of range (valid: [0..={}, 0..={}])",
            n.saturating_sub(1),
            m.saturating_sub(1)
        ),
    ))
}

fn check_max_degree(field: &'static str, d: usize) -> Result<(), EditError> {
    if d > MAX_DEGREE {
        return Err(EditError::new(
            field,
            format!("degree {d} exceeds the supported maximum {MAX_DEGREE}"),
        ));
    }
    Ok(())
}

impl ErbsNet for ErbsCurve {
    type Index = usize;
    type Local = LocalCurve;
    type Knot = f64;
    type Degree = usize;
    type Count = usize;
    type Model = ErbsCurveModel;

    fn of(m: &ErbsCurveModel) -> &Self {
        &m.curve
    }

    fn of_mut(m: &mut ErbsCurveModel) -> &mut Self {
        &mut m.curve
    }

    fn local_at(&self, path: &[usize]) -> Option<&LocalCurve> {
        ErbsCurve::local_at(self, path)
    }

    fn check_path(&self, path: &[usize]) -> Result<(), EditError> {
        let mut level = self;
        for (depth, &l) in path.iter().enumerate() {
            check_count("local", l, level.local_curves().len())
                .map_err(|e| step_error(depth, e))?;
            match (&level.local_curves()[l], depth + 1 < path.len()) {
                (LocalCurve::Erbs(e), true) => level = e,
                (LocalCurve::Spline { .. }, true) => {
                    return Err(EditError::new(
                        "local",
                        format!("step {depth} of the path is a polynomial local: it has no locals"),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn points(local: &LocalCurve) -> Option<&[DVec3]> {
        local.points()
    }

    fn check_point(local: &LocalCurve, p: usize) -> Result<(), EditError> {
        check_count("point", p, local.points().map_or(0, <[DVec3]>::len))
    }

    fn as_erbs(local: &LocalCurve) -> Option<&Self> {
        match local {
            LocalCurve::Erbs(e) => Some(e),
            LocalCurve::Spline { .. } => None,
        }
    }

    fn wrap(e: Self) -> LocalCurve {
        LocalCurve::Erbs(Box::new(e))
    }

    fn transform_local(&mut self, path: &[usize], a: &DMat4) {
        ErbsCurve::transform_local(self, path, a);
    }

    fn translate_local_point(&mut self, path: &[usize], p: usize, d: DVec3) {
        ErbsCurve::translate_local_point(self, path, p, d);
    }

    fn set_local_points(&mut self, path: &[usize], points: &[DVec3]) {
        ErbsCurve::set_local_points(self, path, points);
    }

    fn set_local(&mut self, path: &[usize], local: LocalCurve) {
        ErbsCurve::set_local(self, path, local);
    }

    fn refine(&self, t: f64, degree: Option<usize>) -> Result<Self, GeomError> {
        self.insert_knot(t, degree).map(|(c, _)| c)
    }

    fn build(
        local: &LocalCurve,
        n: usize,
        degree: usize,
        bf: BFunctionKind,
    ) -> Result<Self, GeomError> {
        match local {
            LocalCurve::Spline { curve, .. } => {
                check_build(
                    format_args!("{n} local curves of degree {degree}"),
                    ErbsCurve::from_curve_bytes(n, degree),
                )
                .map_err(|e| GeomError::new("to_erbs", e))?;
                ErbsCurve::from_curve(curve, n, degree, bf, false)
            }
            LocalCurve::Erbs(_) => Err(GeomError::new("to_erbs", "already an ERBS local")),
        }
    }

    fn bfunction(&self) -> BFunctionKind {
        ErbsCurve::bfunction(self)
    }

    fn check_degree(d: usize) -> Result<(), EditError> {
        check_max_degree("degree", d)
    }

    const NOUN: &'static str = "curve";
    const LOCAL_NOUN: &'static str = "local curve";

    fn refinement_change(&self, refined: &Self, t: f64) -> ShapeChange {
        let degree = self.local_curves().iter().map(LocalCurve::degree).max();
        let per = degree.unwrap_or(0) + 1;
        let mut at = erbs_probes(self.knots(), per, Some(self.knots().locate(t)));
        at.push(t);
        shape_change(self, refined, &at)
    }

    fn build_change(local: &LocalCurve, built: &Self) -> ShapeChange {
        let at = erbs_knot_probes(built.knots());
        shape_change(local, &Self::wrap(built.clone()), &at)
    }
}

impl ErbsNet for ErbsSurface {
    type Index = [usize; 2];
    type Local = LocalPatch;
    type Knot = (usize, f64);
    type Degree = [usize; 2];
    type Count = [usize; 2];
    type Model = ErbsSurfaceModel;

    fn of(m: &ErbsSurfaceModel) -> &Self {
        &m.surface
    }

    fn of_mut(m: &mut ErbsSurfaceModel) -> &mut Self {
        &mut m.surface
    }

    fn local_at(&self, path: &[[usize; 2]]) -> Option<&LocalPatch> {
        ErbsSurface::local_at(self, path)
    }

    fn check_path(&self, path: &[[usize; 2]]) -> Result<(), EditError> {
        let mut level = self;
        for (depth, &[k, l]) in path.iter().enumerate() {
            check_pair("local", [k, l], level.count()).map_err(|e| step_error(depth, e))?;
            match (level.local_patch(k, l), depth + 1 < path.len()) {
                (LocalPatch::Erbs(e), true) => level = e,
                (LocalPatch::Spline { .. }, true) => {
                    return Err(EditError::new(
                        "local",
                        format!("step {depth} of the path is a polynomial patch: it has no locals"),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn points(local: &LocalPatch) -> Option<&[DVec3]> {
        local.net().map(|(_, p)| p)
    }

    fn check_point(local: &LocalPatch, p: [usize; 2]) -> Result<(), EditError> {
        check_pair("point", p, local.net().map_or([0, 0], |(c, _)| c))
    }

    fn as_erbs(local: &LocalPatch) -> Option<&Self> {
        match local {
            LocalPatch::Erbs(e) => Some(e),
            LocalPatch::Spline { .. } => None,
        }
    }

    fn wrap(e: Self) -> LocalPatch {
        LocalPatch::Erbs(Box::new(e))
    }

    fn transform_local(&mut self, path: &[[usize; 2]], a: &DMat4) {
        ErbsSurface::transform_local(self, path, a);
    }

    fn translate_local_point(&mut self, path: &[[usize; 2]], p: [usize; 2], d: DVec3) {
        ErbsSurface::translate_local_point(self, path, p, d);
    }

    fn set_local_points(&mut self, path: &[[usize; 2]], points: &[DVec3]) {
        ErbsSurface::set_local_points(self, path, points);
    }

    fn set_local(&mut self, path: &[[usize; 2]], local: LocalPatch) {
        ErbsSurface::set_local(self, path, local);
    }

    fn refine(
        &self,
        (dir, t): (usize, f64),
        degree: Option<[usize; 2]>,
    ) -> Result<Self, GeomError> {
        if dir > 1 {
            return Err(GeomError::new("insert_knot", "the direction is u or v"));
        }
        self.insert_knot(dir, t, degree).map(|(s, _)| s)
    }

    fn build(
        local: &LocalPatch,
        count: [usize; 2],
        degree: [usize; 2],
        bf: BFunctionKind,
    ) -> Result<Self, GeomError> {
        match local {
            LocalPatch::Spline { surface, .. } => {
                check_build(
                    format_args!(
                        "{}×{} local patches of degree [{}, {}]",
                        count[0], count[1], degree[0], degree[1]
                    ),
                    ErbsSurface::from_surface_bytes(count, degree),
                )
                .map_err(|e| GeomError::new("to_erbs", e))?;
                ErbsSurface::from_surface(surface, count, degree, bf, [false, false])
            }
            LocalPatch::Erbs(_) => Err(GeomError::new("to_erbs", "already an ERBS local")),
        }
    }

    fn bfunction(&self) -> BFunctionKind {
        ErbsSurface::bfunction(self)
    }

    fn check_degree([du, dv]: [usize; 2]) -> Result<(), EditError> {
        check_max_degree("degree", du.max(dv))
    }

    const NOUN: &'static str = "surface";
    const LOCAL_NOUN: &'static str = "local patch";

    /// On a grid: the knots and two parameters inside each interval beside the refined one in
    /// its direction, against every knot of the other, and the line u = t (or v = t) there too
    /// (the new patches interpolate at their knot crossings). Fewer probes than a curve gets:
    /// an ERBS surface point costs a few microseconds, and a misplaced restriction of a row of
    /// patches shows all along it.
    fn refinement_change(&self, refined: &Self, (dir, t): (usize, f64)) -> ShapeChange {
        let knots = self.knots();
        let mut beside = [0, 1].map(|d| erbs_probes(&knots[d], 0, None));
        beside[dir] = erbs_probes(&knots[dir], 2, Some(knots[dir].locate(t)));
        let mut line = [0, 1].map(|d| erbs_knot_probes(&knots[d]));
        line[dir] = vec![t];
        shape_change(self, refined, &beside).worse(shape_change(self, refined, &line))
    }

    fn build_change(local: &LocalPatch, built: &Self) -> ShapeChange {
        let at = built.knots().each_ref().map(erbs_knot_probes);
        shape_change(local, &Self::wrap(built.clone()), &at)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::BezierCurve;
    use crate::geom::erbs::ErbsKnots;

    /// Four cubic locals on knots 0..3.
    fn curve() -> ErbsCurve {
        let local = (0..4)
            .map(|l| {
                let x = l as f64;
                BezierCurve::new(vec![
                    DVec3::new(x - 1.0, 0.3 * x, 0.0),
                    DVec3::new(x - 0.3, 1.0 + x.sin(), 0.5),
                    DVec3::new(x + 0.3, -0.5, 0.2 * x),
                    DVec3::new(x + 1.0, 0.1, 0.0),
                ])
                .unwrap()
            })
            .collect();
        ErbsCurve::new(
            vec![0., 0., 1., 2., 3., 3.],
            local,
            BFunctionKind::default(),
        )
        .unwrap()
    }

    /// Negative controls: refinement and construction keep the shape where they promise to,
    /// and a local moved there, by 1e-6 of the size, is caught.
    #[test]
    fn erbs_refinement_and_construction_are_compared_where_they_keep_the_shape() {
        let c = curve();
        let (refined, new) = c.insert_knot(1.5, None).unwrap();
        assert!(c.refinement_change(&refined, 1.5).is_kept());
        // The local beside the refined interval (its restriction), and the new local at t.
        for local in [0, new] {
            let mut moved = refined.clone();
            moved.transform_local(&[local], &DMat4::from_translation(DVec3::Y * 1e-5));
            let change = c.refinement_change(&moved, 1.5);
            assert!(!change.is_kept(), "local {local}: {change:?}");
        }
        let local = c.local_curves()[2].clone();
        let built = ErbsCurve::build(&local, 3, 3, BFunctionKind::default()).unwrap();
        assert!(ErbsCurve::build_change(&local, &built).is_kept());
        let mut moved = built.clone();
        moved.transform_local(&[1], &DMat4::from_translation(DVec3::X * 1e-5));
        assert!(!ErbsCurve::build_change(&local, &moved).is_kept());
        let knots = ErbsKnots::open(vec![0., 0., 1., 2., 3., 3.], 4).unwrap();
        assert_eq!(erbs_knot_probes(&knots), vec![0., 1., 2., 3.]);
    }
}
