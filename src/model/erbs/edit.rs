//! The ERBS edits, written once for curves and surfaces through [`ErbsNet`].

use super::*;
use crate::geom::erbs::{ErbsCurve, ErbsSurface, MAX_NESTING};
use crate::geom::shape::ShapeChange;
use crate::geom::{BFunctionKind, GeomError};
use crate::model::edit::{Build, EditError, IntoObject, KindEdit, Target, check_shape_kept};
use crate::model::points::check_vector;
use crate::model::{Index2, MAX_DEGREE};
use glam::{DMat4, DVec3, DVec4};
use std::fmt::Debug;
use std::hash::Hash;

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
    /// `model` with this net in place of its own (same sample counts).
    fn in_model(self, model: &Self::Model) -> Self::Model;

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
    /// What [`ErbsNet::build`] with these counts allocates, in words and bytes.
    fn build_size(count: Self::Count, degree: Self::Degree) -> (String, u128);
    /// The count of `side` locals per direction, and how many locals a count makes.
    fn count_of(side: usize) -> Self::Count;
    fn locals_in(count: Self::Count) -> u128;
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
pub(super) fn check_affine(m: &DMat4) -> Result<(), EditError> {
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

pub(super) fn local_of<'a, N: ErbsNet>(
    net: &'a N,
    path: &LocalPath<N::Index>,
) -> Result<&'a N::Local, EditError> {
    net.check_path(path.steps())?;
    net.local_at(path.steps())
        .ok_or_else(|| EditError::new("local", format!("no local at {:?}", path.steps())))
}

/// The error for step `depth` of a path (`what` the index problem).
pub(super) fn step_error(depth: usize, what: EditError) -> EditError {
    if depth == 0 {
        what
    } else {
        EditError::new(
            "local",
            format!("step {depth} of the path: {}", what.message),
        )
    }
}

pub(super) fn polynomial_points<N: ErbsNet>(local: &N::Local) -> Result<&[DVec3], EditError> {
    N::points(local).ok_or_else(|| {
        EditError::new(
            "point",
            "an ERBS local has no control points of its own: address one of its locals",
        )
    })
}

pub(super) fn geom(e: GeomError) -> EditError {
    EditError::new(e.field, e.message)
}

impl<N: ErbsNet> ErbsEdit<N> {
    /// Checks the edit; a structural edit hands back the net it leaves (see
    /// [`KindEdit::prepare`]).
    fn prepare_net(&self, net: &N) -> Result<Option<N>, EditError> {
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
                .map(|()| None)
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
                )?;
                Ok(Some(match local {
                    None => refined,
                    Some(path) => with_local(net, path, N::wrap(refined)),
                }))
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
                check_shape_kept("to_erbs", N::LOCAL_NOUN, N::build_change(l, &built))?;
                Ok(Some(with_local(net, local, N::wrap(built))))
            }
            // Puts one local back in place (cheaper than a copy of the net).
            ErbsEdit::SetLocal { local, .. } => local_of(net, local).map(|_| None),
            ErbsEdit::Restore(to) => Ok(Some((**to).clone())),
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
    ErbsEdit<N>: IntoObject<Object = crate::model::ObjectEdit>,
{
    type Model = N::Model;

    fn prepare(&self, m: &N::Model) -> Result<Option<N::Model>, EditError> {
        let after = self.prepare_net(N::of(m))?;
        Ok(after.map(|net| net.in_model(m)))
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

    fn builds(&self) -> Option<Build> {
        match self {
            ErbsEdit::ToErbs {
                local,
                count,
                degree,
            } => {
                let (what, bytes) = N::build_size(*count, *degree);
                let proxy = |side: usize| {
                    let count = N::count_of(side);
                    let edit = ErbsEdit::ToErbs {
                        local: *local,
                        count,
                        degree: *degree,
                    };
                    (N::locals_in(count), edit.into_object())
                };
                Some(Build {
                    field: "to_erbs",
                    what,
                    bytes,
                    locals: N::locals_in(*count),
                    proxies: vec![proxy(BUILD_PROXY_SIDES[0]), proxy(BUILD_PROXY_SIDES[1])],
                })
            }
            _ => None,
        }
    }
}

/// Locals per direction of the two small builds whose needs the editor extrapolates from: past
/// the few locals where the samples in their supports still weigh, each local costs the same.
const BUILD_PROXY_SIDES: [usize; 2] = [8, 16];

/// Applies `edit` to `model` (taking its prepared `result` where there is one) and hands back
/// the model as it was, for samplers that follow a refinement from the old net to the new one.
pub(super) fn apply_keeping_old<N: ErbsNet>(
    edit: &ErbsEdit<N>,
    model: &mut N::Model,
    result: Option<N::Model>,
) -> N::Model
where
    ErbsEdit<N>: KindEdit<Model = N::Model>,
{
    match result {
        Some(after) => std::mem::replace(model, after),
        None => {
            let old = model.clone();
            edit.apply(model);
            old
        }
    }
}

/// `net` with the local at `path` replaced by `local`.
fn with_local<N: ErbsNet>(net: &N, path: &LocalPath<N::Index>, local: N::Local) -> N {
    let mut out = net.clone();
    out.set_local(path.steps(), local);
    out
}

pub(super) fn check_count(field: &'static str, i: usize, n: usize) -> Result<(), EditError> {
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

pub(super) fn check_pair(
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

pub(super) fn check_max_degree(field: &'static str, d: usize) -> Result<(), EditError> {
    if d > MAX_DEGREE {
        return Err(EditError::new(
            field,
            format!("degree {d} exceeds the supported maximum {MAX_DEGREE}"),
        ));
    }
    Ok(())
}
